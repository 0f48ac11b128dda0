"""Open the built book in a real headless browser, offline, page by page.

For every page in ``_toc.yml`` this checks what a reader would see in
``_build/html`` served from localhost in Debian's Chromium (driven by Playwright
for Python, with the system browser: no ``playwright install``):

- nothing is fetched from anywhere but localhost (every other request is
  aborted and reported): the book renders offline;
- no console errors and no uncaught JavaScript exceptions;
- every image has loaded (``naturalWidth > 0``);
- every formula is typeset by MathJax (no raw TeX left, no MathJax errors);
- no executed cell shows an error (traceback or ``Traceback`` on stderr);
- saved widgets and matplotlib animations are drawn;
- no code line runs past its block, hidden behind a sideways scroll (long lines
  wrap: book/_css/pgae.css), at 1280 px and at a phone's 400 px;
- no page scrolls sideways at a phone's 390 px nor at 1280 px, and nothing in the
  text is cut off at the edge of a box (a wide table or formula scrolls in its own
  box, a plot shrinks, a message wraps: book/_css/pgae.css); the live boxes of
  chapters 05 and 08 are run first, so that their messages and plots are measured;
- every link to a page of the book (navigation, sidebar, prev/next, text)
  answers HTTP 200;
- with no repository address, no launch, repository or issues button; every
  chapter has a link to download it as a notebook.

A full-page screenshot of each page goes to ``_build/screenshots/`` with a
``report.json`` of what was found and how long each page took; beside them the
top of each page at 390 px (``390px-<page>.png``), its live box at 390 px, and
chapter 08 at 1280 px (``1280px-notebooks_08_playground.png``). The module is
skipped when the book has not been built, or (unless
``PGAE_BROWSER_REQUIRED=1``, as in ``.ci/test``) when Chromium or Playwright is
missing. Run it after ``jupyter-book build .``:
``python -m pytest tests/test_book_browser.py``; ``PGAE_BOOK_SITE=<folder>``
checks a book built elsewhere.
"""
from __future__ import annotations

import functools
import json
import os
import re
import time
import urllib.error
import urllib.request
from pathlib import Path

import pytest
import yaml
from browser_support import CHROMIUM, CHROMIUM_FLAGS, KNOWN_CONSOLE_ERRORS, serve

ROOT = Path(__file__).resolve().parents[1]
BOOK = Path(os.environ.get("PGAE_BOOK_SITE", ROOT / "_build" / "html"))  # the built book
SCREENSHOTS = ROOT / "_build" / "screenshots"


def _missing_browser() -> str | None:
    if not Path(CHROMIUM).exists():
        return f"no Chromium at {CHROMIUM} (apt-get install chromium)"
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError:
        return "Playwright for Python is not installed (pip install playwright)"
    return None


if not (BOOK / "index.html").exists():
    pytest.skip(f"no built book in {BOOK}: run `jupyter-book build .` first", allow_module_level=True)
if (_why := _missing_browser()) is not None:
    if os.environ.get("PGAE_BROWSER_REQUIRED") == "1":  # as in .ci/test: fail, don't skip
        raise RuntimeError(_why)
    pytest.skip(_why, allow_module_level=True)

from playwright.sync_api import Error as BrowserError  # noqa: E402 -- only once the browser is known to be there
from playwright.sync_api import sync_playwright  # noqa: E402


def toc_pages() -> list[str]:
    """Every page of _toc.yml, in reading order, as paths without suffix."""
    toc = yaml.safe_load((ROOT / "_toc.yml").read_text(encoding="utf-8"))
    pages = [toc["root"]]

    def walk(entries):
        for entry in entries or []:
            if "file" in entry:
                pages.append(entry["file"])
            walk(entry.get("sections"))
            walk(entry.get("chapters"))

    walk(toc.get("parts", []) + toc.get("chapters", []) + toc.get("sections", []))
    return pages


PAGES = toc_pages()
REPORT: dict[str, dict] = {}


@pytest.fixture(scope="module")
def site():
    """The built book served on a free localhost port, in a thread."""
    address, server = serve(BOOK)
    yield address
    server.shutdown()
    SCREENSHOTS.mkdir(parents=True, exist_ok=True)
    (SCREENSHOTS / "report.json").write_text(json.dumps(REPORT, indent=1), encoding="utf-8")


@pytest.fixture(scope="module")
def browser():
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_FLAGS)
        yield browser
        browser.close()


DIRECT = urllib.request.build_opener(urllib.request.ProxyHandler({}))  # localhost: no proxy


@functools.cache
def http_status(url: str) -> int:
    try:
        with DIRECT.open(url, timeout=10) as response:
            return response.status
    except urllib.error.HTTPError as error:
        return error.code


# Run in the page once it has loaded: wait for the images, then look at what it shows.
INSPECT = r"""async () => {
  // Images below the fold may be lazy: load them all, then wait for each.
  const imgs = [...document.images];
  imgs.forEach(img => { img.loading = "eager"; });
  await Promise.all(imgs.map(img => img.complete ? null
      : new Promise(done => { img.onload = img.onerror = done; })));
  // MathJax (deferred script) typesets once at start-up: wait for it.
  if (window.MathJax && MathJax.startup && MathJax.startup.promise) await MathJax.startup.promise;
  const main = document.querySelector("main") || document.body;
  // Text outside code, formulas and scripts, where raw TeX would show.
  const texts = [];
  const walker = document.createTreeWalker(main, NodeFilter.SHOW_TEXT, {acceptNode: n =>
      n.parentElement.closest("pre, code, script, style, textarea, mjx-container, .highlight")
        ? NodeFilter.FILTER_REJECT : NodeFilter.FILTER_ACCEPT});
  while (walker.nextNode()) texts.push(walker.currentNode.textContent);
  return {
    images: imgs.length,
    brokenImages: imgs.filter(i => !(i.complete && i.naturalWidth > 0))
                      .map(i => i.currentSrc || i.src),
    formulas: document.querySelectorAll(".math").length,
    untypeset: [...document.querySelectorAll(".math")]
        .filter(m => !m.querySelector("mjx-container")).map(m => m.textContent.slice(0, 80)),
    // A TeX error shows as mjx-merror; an undefined macro as its name in red (MathJax's
    // noundefined extension): the textContent of either is the faulty TeX.
    mathErrors: [...document.querySelectorAll('mjx-merror, mjx-mtext[style*="color: red"]')]
        .map(m => m.closest("mjx-container").parentElement.textContent.slice(0, 80)),
    text: texts.join(" "),
    errorOutputs: [...main.querySelectorAll(".output.error, .output.traceback")]
        .map(e => e.textContent.slice(0, 300)),
    stderr: [...main.querySelectorAll(".output.stderr")].map(e => e.textContent.slice(0, 300)),
    widgetViews: main.querySelectorAll('script[type="application/vnd.jupyter.widget-view+json"]').length,
    // The widget manager draws each saved view into a .widget-subarea beside its tag.
    widgetsDrawn: main.querySelectorAll(".widget-subarea .jupyter-widgets").length,
    widgetAreas: main.querySelectorAll(".widget-subarea").length,
    animations: main.querySelectorAll(".animation").length,
    animationIcons: main.querySelectorAll(".animation .anim-buttons svg").length,
    links: [...document.querySelectorAll("a[href]")].map(a => a.href),
  };
}"""
# The book's repository address (empty: none), and links that need one: launch services, the repository's pages.
REPOSITORY_URL = (yaml.safe_load((ROOT / "_config.yml").read_text(encoding="utf-8")).get("repository") or {}).get("url")
LAUNCH = re.compile(r"colab\.research\.google\.com|mybinder\.org|github\.com/[^/]+/pgae_lite|/issues(/|$)")
# Raw TeX that MathJax should have replaced: \( \) \[ \] $$, $x$ and \begin{...}.
RAW_TEX = re.compile(r"\\\(|\\\)|\\\[|\\\]|\$\$|\$[^\s$][^$\n]{0,200}?[^\s$\\]\$|\\begin\{")


@pytest.mark.parametrize("docname", PAGES)
def test_page_renders_offline(docname, site, browser):
    started = time.perf_counter()
    found: dict[str, list] = {"external_requests": [], "console_errors": [], "http_errors": []}
    context = browser.new_context(viewport={"width": 1280, "height": 900})

    def route(route):  # the book must render offline: only localhost may be asked
        if route.request.url.startswith(site):
            route.continue_()
        else:
            found["external_requests"].append(route.request.url)
            route.abort()

    context.route("**/*", route)
    page = context.new_page()
    page.on("console", lambda msg: msg.type == "error" and found["console_errors"].append(msg.text))
    page.on("pageerror", lambda exc: found["console_errors"].append(f"uncaught: {exc}"))
    page.on("response", lambda r: r.status >= 400 and found["http_errors"].append(f"{r.status} {r.url}"))

    response = page.goto(f"{site}/{docname}.html", wait_until="load")
    assert response is not None and response.status == 200, f"{docname}.html: {response and response.status}"
    seen = page.evaluate(INSPECT)
    page.wait_for_timeout(300)  # let late console messages (fonts, widgets) arrive
    checked = time.perf_counter()
    SCREENSHOTS.mkdir(parents=True, exist_ok=True)
    # The API page is 170,000 px tall at 1280 px: its full-page screenshot takes 20-30 s on a busy machine.
    page.screenshot(path=str(SCREENSHOTS / f"{docname.replace('/', '_')}.png"), full_page=True, timeout=120_000)
    screenshot_seconds = time.perf_counter() - checked
    context.close()

    known = [e for e in found["console_errors"] if any(p.search(e) for p in KNOWN_CONSOLE_ERRORS)]
    found["console_errors"] = [e for e in found["console_errors"] if e not in known]
    found["broken_images"] = seen["brokenImages"]
    found["untypeset_formulas"] = seen["untypeset"] + seen["mathErrors"]
    found["raw_tex"] = [m.group(0) for m in RAW_TEX.finditer(seen["text"])]
    found["error_outputs"] = seen["errorOutputs"] + [s for s in seen["stderr"] if "Traceback" in s]
    found["widgets_not_drawn"] = ([f"{seen['widgetViews']} saved widget views, {seen['widgetAreas']} drawn"]
                                  if seen["widgetViews"] > min(seen["widgetAreas"], seen["widgetsDrawn"]) else [])
    found["animations_without_icons"] = (["animation buttons have no icons"]
                                         if seen["animations"] and not seen["animationIcons"] else [])
    # Links into the book (navigation, prev/next, cross-references) must lead to a page.
    internal = {link.split("#")[0] for link in seen["links"] if link.startswith(site)}
    found["broken_links"] = sorted(url for url in internal if http_status(url) != 200)
    # No dead links: with no repository address (_config.yml's repository.url, book/_ext/repository_links.py)
    # no launch, repository or issues button; every chapter downloadable as its notebook.
    if not REPOSITORY_URL:
        found["links_to_no_repository"] = sorted({link for link in seen["links"] if LAUNCH.search(link)})
    if docname.startswith("notebooks/") and not any(link.split("#")[0].endswith(".ipynb") for link in internal):
        found["no_notebook_download"] = [f"{docname}: no link to its .ipynb"]

    REPORT[docname] = {
        "seconds": round(time.perf_counter() - started, 2),
        "screenshot_seconds": round(screenshot_seconds, 2),
        "known_console_errors": known,
        "formulas": seen["formulas"], "images": seen["images"],
        "widget_views": seen["widgetViews"], "animations": seen["animations"],
        "stderr_outputs": seen["stderr"], "internal_links": len(internal),
        **found,
    }
    problems = {k: v for k, v in found.items() if v}
    assert not problems, f"{docname}: " + json.dumps(problems, indent=1)


# Run in the page: every code block (a cell's input, a printed output, a code block in the text)
# whose lines run past its width, so that their ends hide behind a sideways scroll. For each such
# block, the lines wider than the block (measured unwrapped, in the block's own font).
CUT_CODE = r"""async () => {
  await document.fonts.ready;
  const article = document.querySelector("article.bd-article") || document.body;
  const cut = [];
  for (const pre of new Set(article.querySelectorAll("div.cell_input pre, div.highlight pre"))) {
    if (pre.scrollWidth <= pre.clientWidth + 1) continue;
    const style = getComputedStyle(pre);
    const room = pre.clientWidth - parseFloat(style.paddingLeft) - parseFloat(style.paddingRight);
    const lines = pre.textContent.replace(/\n$/, "").split("\n");
    const probe = pre.appendChild(document.createElement("span"));
    probe.style.cssText = "white-space: pre; position: absolute; visibility: hidden;";
    const wide = lines.filter(line => {
      probe.textContent = line;
      return probe.getBoundingClientRect().width > room + 1;
    });
    probe.remove();
    cut.push({scrollWidth: pre.scrollWidth, clientWidth: pre.clientWidth,
              lines: (wide.length ? wide : lines).map(line => line.slice(0, 80))});
  }
  return cut;
}"""


@pytest.mark.parametrize("width", [1280, 400], ids=["desktop", "narrow"])
@pytest.mark.parametrize("docname", PAGES)
def test_code_lines_not_cut_off(docname, width, site, browser):
    """No code line runs past its block: long lines wrap (book/_css/pgae.css), at the other
    tests' viewport and at a phone's width."""
    context = browser.new_context(viewport={"width": width, "height": 900})
    context.route("**/*", lambda route: route.continue_() if route.request.url.startswith(site) else route.abort())
    page = context.new_page()
    response = page.goto(f"{site}/{docname}.html", wait_until="load")
    assert response is not None and response.status == 200, f"{docname}.html: {response and response.status}"
    cut = page.evaluate(CUT_CODE)
    context.close()
    lines = [line for block in cut for line in block["lines"]]
    assert not cut, (f"{docname} at {width} px: {len(lines)} code lines in {len(cut)} blocks run past "
                     f"the block and are cut off:\n" + "\n".join(lines))


# Run in the page once it has loaded: what makes it wider than the screen, and what a box cuts off.
# An element sticks out when its right edge is past the screen's and no box around it scrolls or
# clips it within the screen (a table scrolling in its output box is fine); an element drawn fixed
# (the theme's sidebars, off-canvas on a phone) or hidden does not widen the page. Only the
# outermost element of each is named. Cut off: in the article, an element that runs more than 2 px
# past the right edge of a box that hides its overflow (overflow: hidden or clip) with no scrolling
# box between them; MathJax's invisible copy of each formula for screen readers is left out.
OVERFLOW = r"""async () => {
  const imgs = [...document.images];
  imgs.forEach(img => { img.loading = "eager"; });
  await Promise.all(imgs.map(img => img.complete ? null
      : new Promise(done => { img.onload = img.onerror = done; })));
  if (window.MathJax && MathJax.startup && MathJax.startup.promise) await MathJax.startup.promise;
  await document.fonts.ready;
  const width = window.innerWidth;
  const name = el => el.tagName.toLowerCase() + [...el.classList].slice(0, 3).map(c => "." + c).join("");
  const describe = el => {
    const r = el.getBoundingClientRect();
    return `${name(el)} in ${name(el.parentElement)} (${Math.round(r.width)} px wide, right edge at ` +
           `${Math.round(r.right)} px): ` + JSON.stringify(el.textContent.replace(/\s+/g, " ").trim().slice(0, 60));
  };
  const sticksOut = el => {
    const r = el.getBoundingClientRect();
    if (!r.width || r.right <= width + 1) return false;
    const style = getComputedStyle(el);
    if (style.position === "fixed" || style.visibility === "hidden") return false;
    for (let box = el.parentElement; box && box !== document.documentElement; box = box.parentElement) {
      const s = getComputedStyle(box);
      if (s.position === "fixed") return false;
      if (s.overflowX !== "visible" && box.getBoundingClientRect().right <= width + 1) return false;
    }
    return true;
  };
  const out = new Set([...document.body.querySelectorAll("*")].filter(sticksOut));
  const cut = [];
  const article = document.querySelector("article.bd-article") || document.body;
  for (const box of article.querySelectorAll("*")) {
    if (!["hidden", "clip"].includes(getComputedStyle(box).overflowX) || box.closest("mjx-assistive-mml")) continue;
    const edge = box.getBoundingClientRect().right;
    for (const el of box.querySelectorAll("*")) {
      if (el.closest("mjx-assistive-mml") || el.getBoundingClientRect().right <= edge + 2) continue;
      let scrolled = false;
      for (let a = el.parentElement; a !== box; a = a.parentElement)
        if (["auto", "scroll"].includes(getComputedStyle(a).overflowX)) { scrolled = true; break; }
      if (!scrolled && el.parentElement.getBoundingClientRect().right <= edge + 2)
        cut.push(`${describe(el)} cut off by ${name(box)}`);
    }
  }
  return {scrollWidth: document.documentElement.scrollWidth, innerWidth: width,
          stickingOut: [...out].filter(el => !out.has(el.parentElement)).map(describe), cutOff: cut};
}"""
# The live boxes, run once before measuring so that their plots and messages are on the page:
# chapter 08's playground (its Run button, the first episode) and chapter 05's box (its sentence).
LIVE_BOXES = {".pgae-live": ("button.pgae-live-run", "dataset.result !== undefined"),
              ".pgae-understood": ("button", "dataset.done === '1'")}


@pytest.mark.parametrize("width", [390, 1280], ids=["phone", "desktop"])
@pytest.mark.parametrize("docname", PAGES)
def test_page_fits_the_screen(docname, width, site, browser):
    """At a phone's 390 px and at 1280 px the page does not scroll sideways and no text is cut off at
    a box's edge: a wide table or formula scrolls in its own box, plots shrink, messages wrap
    (book/_css/pgae.css). Saves the top of each page at 390 px, the live boxes at 390 px and
    chapter 08 at 1280 px."""
    context = browser.new_context(viewport={"width": width, "height": 844 if width < 800 else 900})
    context.route("**/*", lambda route: route.continue_() if route.request.url.startswith(site) else route.abort())
    page = context.new_page()
    response = page.goto(f"{site}/{docname}.html", wait_until="load")
    assert response is not None and response.status == 200, f"{docname}.html: {response and response.status}"
    live_not_run = []
    for selector, (button, done) in LIVE_BOXES.items():
        if page.locator(selector).count():
            try:  # the box's models load, run, and it shows what they said (tests/test_live_playground.py)
                page.locator(f"{selector} {button}").first.click(timeout=60_000)
                page.wait_for_function(f"document.querySelector('{selector}').{done}", timeout=60_000)
            except BrowserError as error:  # measured as it is: whether it runs is test_live_playground.py's
                live_not_run.append(f"{selector}: {type(error).__name__}")
    seen = page.evaluate(OVERFLOW)
    SCREENSHOTS.mkdir(parents=True, exist_ok=True)
    stem = f"{width}px-{docname.replace('/', '_')}"
    if width == 390:  # the top of the page: full pages at 390 px run to 275,000 px (the API page)
        height = min(page.evaluate("document.documentElement.scrollHeight"), 8000)
        page.screenshot(path=str(SCREENSHOTS / f"{stem}.png"), full_page=True,
                        clip={"x": 0, "y": 0, "width": width, "height": height})
        for selector in LIVE_BOXES:
            if page.locator(selector).count():
                page.locator(selector).first.screenshot(path=str(SCREENSHOTS / f"{stem}-live.png"))
    elif docname == "notebooks/08_playground":
        page.screenshot(path=str(SCREENSHOTS / f"{stem}.png"), full_page=True)
    context.close()
    REPORT.setdefault(f"{docname} at {width} px", {}).update(
        scroll_width=seen["scrollWidth"], sticking_out=seen["stickingOut"][:10], cut_off=seen["cutOff"][:10],
        live_boxes_not_run=live_not_run)
    problems = []
    if seen["scrollWidth"] > seen["innerWidth"] + 1:
        problems.append(f"the page scrolls sideways ({seen['scrollWidth']} px wide on a {seen['innerWidth']} px "
                        f"screen); sticking out past the right edge:\n  " + "\n  ".join(seen["stickingOut"][:10]))
    if seen["cutOff"]:
        problems.append(f"{len(seen['cutOff'])} elements cut off at a box's edge:\n  "
                        + "\n  ".join(seen["cutOff"][:10]))
    assert not problems, f"{docname} at {width} px: " + "\n".join(problems)


EMPTY_OUTPUT = re.compile(r"Empty DataFrame|<tbody>\s*</tbody>|^\s*\w[\w ]*:? \{\}\s*$|<td>(?:NaN|nan|None)</td>", re.M)


@pytest.mark.parametrize("docname", PAGES)
def test_no_empty_tables(docname):
    """No output shows an empty table where a lesson asks the reader to compare it: no empty
    DataFrame, no table without rows, no printed empty mapping (``describe {}``), and no table
    cell that reads NaN or None (a figure not measured says so in words)."""
    html = (BOOK / f"{docname}.html").read_text(encoding="utf-8")
    outputs = re.findall(r'<div class="cell_output[^"]*">(.*?)</div>\s*</div>\s*</div>', html, re.S)
    empty = [EMPTY_OUTPUT.search(o).group(0).strip() for o in outputs if EMPTY_OUTPUT.search(o)]
    assert not empty, f"{docname}: {len(empty)} empty outputs: {empty[:5]}"
