"""What the browser checks share: Debian's Chromium, its flags, the console errors we accept, and a quiet
static file server for the built book (tests/test_book_browser.py, tests/test_live_playground.py,
benchmarks/live_playground.py). Importing it needs no built book and no browser.
"""
from __future__ import annotations

import re
import shutil
import threading
from contextlib import contextmanager
from functools import partial
from http.server import SimpleHTTPRequestHandler, ThreadingHTTPServer

CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
# Flags for Chromium as root on a machine without network: no sandbox, no GPU, none
# of its background traffic (updates, sync, first-run pages), no proxy between it and
# localhost. Playwright gives every launch a fresh temporary profile (--user-data-dir).
CHROMIUM_FLAGS = [
    "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
    "--no-proxy-server",
]

# Console errors we accept, each with the reason.
KNOWN_CONSOLE_ERRORS = [
    # sphinx-thebe 0.3.1 declares THEBE_JS_URL twice on every page: harmless, the live
    # code button still works (the thebe library itself is fetched only when clicked).
    re.compile(r"Identifier 'THEBE_JS_URL' has already been declared"),
]


class _QuietHandler(SimpleHTTPRequestHandler):
    def log_message(self, *args):  # keep pytest's output readable
        pass


class _QuietServer(ThreadingHTTPServer):
    def handle_error(self, request, client_address):
        pass  # the browser drops connections it no longer needs (broken pipes): not a failure


def serve(folder) -> tuple[str, ThreadingHTTPServer]:
    """``folder`` served on a free localhost port, in a thread: (its address, the server to shut down)."""
    server = _QuietServer(("127.0.0.1", 0), partial(_QuietHandler, directory=str(folder)))
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return f"http://127.0.0.1:{server.server_address[1]}", server


@contextmanager
def offline_page(folder, path: str):
    """``folder`` served, and ``path`` in it open in Debian's Chromium with every other request aborted and the
    live models loaded (``window.pgae.load()``): yields (the page, the list its console errors collect in)."""
    from playwright.sync_api import sync_playwright

    site, server = serve(folder)
    errors: list[str] = []
    try:
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_FLAGS)
            context = browser.new_context()
            context.route("**/*", lambda r: r.continue_() if r.request.url.startswith(site) else r.abort())
            page = context.new_page()
            page.on("console", lambda m: m.type == "error" and not any(k.search(m.text) for k in KNOWN_CONSOLE_ERRORS)
                    and errors.append(m.text))
            page.on("pageerror", lambda e: not any(k.search(str(e)) for k in KNOWN_CONSOLE_ERRORS)
                    and errors.append(str(e)))
            page.goto(f"{site}/{path}", wait_until="load")
            page.evaluate("window.pgae.load()")
            yield page, errors
            browser.close()
    finally:
        server.shutdown()
