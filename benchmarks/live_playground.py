"""The live playground in headless Chromium: bytes and time to the first result, and per Run.

    python benchmarks/live_playground.py [--book _build/html] [--profile book] [--runs 20]

Takes the built book (``jupyter-book build .``), writes the profile's models and test episodes
into a copy of it (``pgae_lite.web.assets.export_web``, from the cache), serves the copy from
localhost with every other request refused (the network off) and opens chapter 08 in Debian's
Chromium, each time in a fresh browser context (an empty cache), once per model:

- ``bytes_to_first_result``: every response body the page received from navigation until the
  first ``window.pgae.run`` of that model resolved (the page, its scripts and styles, onnxruntime-web,
  the manifest, the episodes, the model); ``live_bytes``: the share of it that the live playground
  alone asked for (``_static/ort/``, ``_static/web/``, ``pgae*.js``);
- ``seconds_to_first_result``: from navigation start to that first result;
- ``seconds_per_run``: the median of ``--runs`` further runs on other test episodes.

Then, for the PGAE-BERT models, free text (the project's paraphrases, bert/paraphrases.tsv), in the
same page: ``free_text_bytes``, every response body from the first free text until its result (the
tokenizer, the sentence encoder, the model's head and word table); ``seconds_to_first_free_text``;
``seconds_per_free_text`` (the median over ``--runs`` further sentences); and ``parity``: every
paraphrase run in the page against PyTorch (:func:`pgae_lite.web.sentence.free_text_reference`): the
words and readbacks that differ, and the largest joint difference relative to the joint range.

Writes results/live_playground.json. The budget (issue 47): the closed-vocabulary playground
answers within 3 s of opening the page and adds at most 20 MB; free text at most 50 MB more, loaded
only when asked for.
"""
from __future__ import annotations

import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

from harness import ROOT, Benchmark

sys.path.insert(0, str(ROOT / "tests"))
from browser_support import CHROMIUM, CHROMIUM_FLAGS, serve  # noqa: E402

from pgae_lite.bert.paraphrases import load_paraphrases  # noqa: E402
from pgae_lite.web.assets import MODELS, export_web  # noqa: E402

LIVE = ("/_static/ort/", "/_static/web/", "/_static/pgae", "/_static/tokenizers/")


def measure(site: str, browser, model: str, runs: int) -> dict:
    context = browser.new_context()
    received: list[tuple[str, int]] = []
    context.route("**/*", lambda r: r.continue_() if r.request.url.startswith(site) else r.abort())
    page = context.new_page()

    def body_size(response):
        try:
            received.append((response.url, len(response.body())))
        except Exception:  # noqa: BLE001 -- a redirect or an aborted response has no body
            pass
    page.on("response", body_size)
    t0 = time.perf_counter()
    page.goto(f"{site}/notebooks/08_playground.html", wait_until="domcontentloaded")
    episodes = page.evaluate("window.pgae.load().then(m => m.episodes.map(e => e.id))")
    page.evaluate("([model, episode]) => window.pgae.run({model, signal: 'execute', episode})", [model, episodes[0]])
    first = time.perf_counter() - t0
    page.wait_for_timeout(200)                                    # responses still being counted
    total = sum(n for _, n in received)
    live = sum(n for url, n in received if any(part in url for part in LIVE))
    per_run = []
    for episode in episodes[1:runs + 1]:
        t = time.perf_counter()
        page.evaluate("([model, episode]) => window.pgae.run({model, signal: 'execute', episode})", [model, episode])
        per_run.append(time.perf_counter() - t)
    result = {"model": model, "bytes_to_first_result": total, "live_bytes": live,
              "seconds_to_first_result": round(first, 3), "seconds_per_run": round(statistics.median(per_run), 4),
              "runs": len(per_run)}
    if page.evaluate("(model) => window.pgae.manifest().models[model].reads") == "features":
        result |= free_text(page, received, model, episodes, runs)
    context.close()
    return result


RUN_TEXT = "([model, episode, text]) => window.pgae.run({model, signal: 'execute', episode, text})"


def free_text(page, received: list, model: str, episodes: list[str], runs: int) -> dict:
    """The first free text's bytes and time, then the time per further sentence, in the same page."""
    texts = [p.text for p in load_paraphrases()]
    received.clear()
    t = time.perf_counter()
    page.evaluate(RUN_TEXT, [model, episodes[0], texts[0]])
    first = time.perf_counter() - t
    page.wait_for_timeout(200)
    per_run = []
    for i, text in enumerate(texts[1:runs + 1], 1):
        t = time.perf_counter()
        page.evaluate(RUN_TEXT, [model, episodes[i % len(episodes)], text])
        per_run.append(time.perf_counter() - t)
    return {"free_text_bytes": sum(n for _, n in received), "seconds_to_first_free_text": round(first, 3),
            "seconds_per_free_text": round(statistics.median(per_run), 4)}


def parity(site: str, browser, name: str, profile: str, seed: int) -> dict:
    """Every paraphrase in the page against PyTorch: words, readbacks and joints."""
    import numpy as np

    from pgae_lite.runs.pipeline import simulated_dataset, trained_pgae
    from pgae_lite.web.sentence import free_text_reference

    run = trained_pgae(MODELS[name], profile, seed, device="cpu", progress=False)
    test = simulated_dataset(profile, "cpu", progress=False).split("test")
    texts = [p.text for p in load_paraphrases()]
    want = free_text_reference(run.model, run.normaliser, test, texts)
    context = browser.new_context()
    context.route("**/*", lambda r: r.continue_() if r.request.url.startswith(site) else r.abort())
    page = context.new_page()
    page.goto(f"{site}/notebooks/08_playground.html", wait_until="domcontentloaded")
    got = page.evaluate("""async ([model, texts, ids]) => {
        const out = [];
        for (let i = 0; i < texts.length; i++) out.push(await window.pgae.run({model, signal: "execute",
                                                                              episode: ids[i], text: texts[i]}));
        return out; }""", [name, texts, [w["episode"] for w in want]])
    context.close()
    span = float(run.normaliser.joints[1] - run.normaliser.joints[0])
    differ = [t for t, r, w in zip(texts, got, want) if r["words"] != w["words"]]
    back = [t for t, r, w in zip(texts, got, want) if r["understood"] != w["understood"]]
    joints = max(float(np.abs(np.array(r["joints"]) - w["joints"]).max()) for r, w in zip(got, want)) / span
    return {"model": name, "sentences": len(texts), "words_differ": len(differ), "readbacks_differ": len(back),
            "differing": sorted(set(differ + back)), "max_joint_difference_of_range": joints}


def main() -> None:
    bench = Benchmark("live_playground", __doc__)
    bench.parser.add_argument("--book", default=str(ROOT / "_build" / "html"), help="the built book")
    bench.parser.add_argument("--runs", type=int, default=20, help="runs timed after the first, per model")
    args = bench.parse()
    from playwright.sync_api import sync_playwright

    with tempfile.TemporaryDirectory() as tmp:
        site_dir = Path(tmp) / "html"
        shutil.copytree(args.book, site_dir)
        shutil.rmtree(site_dir / "_static" / "web", ignore_errors=True)
        manifest = export_web(site_dir / "_static" / "web", args.profile, args.seeds[0])
        static = site_dir / "_static"
        files = {p.relative_to(static).as_posix(): p.stat().st_size
                 for folder in ("web", "ort", "tokenizers") for p in (static / folder).rglob("*") if p.is_file()}
        site, server = serve(site_dir)
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_FLAGS)
            models = [measure(site, browser, name, args.runs) for name in manifest["models"]]
            free = [parity(site, browser, name, manifest["profile"], args.seeds[0])
                    for name, m in manifest["models"].items() if m["reads"] == "features"]
            browser.close()
        server.shutdown()
    for m in models:
        print(m, flush=True)
    for m in free:
        print(m, flush=True)
    bench.write({"models": models, "free_text_parity": free, "files": files, "episodes": len(manifest["episodes"]),
                 "transformer_weights": "float16", "vendored": {"onnxruntime-web": "1.30.0",
                                                               "@huggingface/tokenizers": "0.2.0"},
                 "budget": {"seconds_to_first_result": 3.0, "live_megabytes": 20.0, "free_text_megabytes": 50.0},
                 "within_budget": all(m["seconds_to_first_result"] <= 3.0 and m["live_bytes"] <= 20e6
                                      and m.get("free_text_bytes", 0) <= 50e6 for m in models)})


if __name__ == "__main__":
    main()
