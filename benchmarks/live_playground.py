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
- ``seconds_per_run``: the median of ``--runs`` further runs on other test episodes;
- ``training_episode_bytes``, ``seconds_to_first_training_episode``: the first run on an episode from
  training (the page fetches their file then).

Then, for the PGAE-BERT models, free text (the project's paraphrases, freeform/paraphrases.tsv), in the
same page: ``free_text_bytes``, every response body from the first free text until its result (the
tokenizer, the sentence encoder, the model's head and word table); ``seconds_to_first_free_text``;
``seconds_per_free_text`` (the median over ``--runs`` further sentences); and ``parity``: every
paraphrase, and ``--per-kind`` sentences of each kind of the refusal grammar (freeform/refusal_grammar.py), run in the
page against Python (:func:`pgae_lite.web.sentence.free_text_reference` and the refusal rule): the texts
whose refusal, words or readback differ, and the largest joint difference relative to the joint range;
then the same parity with the encoder's weights in float32 (``export-web --float32``).

Writes results/live_playground.json. The budget (issue 47): the closed-vocabulary playground
answers within 3 s of opening the page and adds at most 20 MB; free text at most 50 MB more, loaded
only when asked for.
"""
from __future__ import annotations

import json
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

from harness import ROOT, Benchmark

sys.path.insert(0, str(ROOT / "tests"))
from browser_support import CHROMIUM, CHROMIUM_FLAGS, serve  # noqa: E402

from pgae_lite.freeform.paraphrases import load_paraphrases  # noqa: E402
from pgae_lite.web.assets import MODELS, export_web  # noqa: E402

LIVE = ("/_static/ort/", "/_static/web/", "/_static/pgae", "/_static/tokenizers/")
# What only free text fetches: the tokenizer and its library, the transformer, the heads, word tables, refusals
FREE = ("/web/tokenizer/", "/tokenizers/", "transformer.onnx", ".head.onnx", ".words.json", "refusals.js")


def body_size(response) -> int:
    """The bytes of a response's body: its Content-Length (the static server sends it for every file; a large
    body may already be gone from the browser's inspector cache when asked for), else the body itself."""
    if "content-length" in response.headers:
        return int(response.headers["content-length"])
    try:
        return len(response.body())
    except Exception:  # noqa: BLE001 -- a redirect or an aborted response has no body
        return 0


def measure(site: str, browser, model: str, runs: int) -> dict:
    context = browser.new_context()
    received: list[tuple[str, int]] = []
    context.route("**/*", lambda r: r.continue_() if r.request.url.startswith(site) else r.abort())
    page = context.new_page()

    page.on("response", lambda response: received.append((response.url, body_size(response))))
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
    trained_on = page.evaluate("window.pgae.manifest().episodes.filter(e => e.split === 'train').map(e => e.id)")
    received.clear()
    t = time.perf_counter()                                       # the first training episode: its file on demand
    page.evaluate("([model, episode]) => window.pgae.run({model, signal: 'execute', episode})", [model, trained_on[0]])
    first_train = time.perf_counter() - t
    page.wait_for_timeout(200)
    result = {"model": model, "bytes_to_first_result": total, "live_bytes": live,
              "seconds_to_first_result": round(first, 3), "seconds_per_run": round(statistics.median(per_run), 4),
              "runs": len(per_run), "training_episode_bytes": sum(n for _, n in received),
              "seconds_to_first_training_episode": round(first_train, 3)}
    if page.evaluate("(model) => window.pgae.manifest().models[model].reads", model) == "features":
        result |= free_text(page, received, model, episodes, runs)
    context.close()
    return result


RUN_TEXT = """([model, episode, text]) => window.pgae.run({model, signal: 'execute', episode, text})
                                  .then(() => true, () => false)"""     # a refused text counts too


def free_text(page, received: list, model: str, episodes: list[str], runs: int) -> dict:
    """The first free text's bytes and time, then the time per further sentence, in the same page; each
    paraphrase on a test episode with its cube."""
    scenes = page.evaluate("window.pgae.manifest().episodes.map(e => e.scene)")
    said = [(p.text, next((e for e, s in zip(episodes, scenes) if p.colour in s), episodes[0]))
            for p in load_paraphrases()[:runs + 1]]
    received.clear()
    t = time.perf_counter()
    page.evaluate(RUN_TEXT, [model, said[0][1], said[0][0]])
    first = time.perf_counter() - t
    page.wait_for_timeout(200)
    per_run = []
    for text, episode in said[1:]:
        t = time.perf_counter()
        page.evaluate(RUN_TEXT, [model, episode, text])
        per_run.append(time.perf_counter() - t)
    return {"free_text_bytes": sum(n for _, n in received), "seconds_to_first_free_text": round(first, 3),
            "seconds_per_free_text": round(statistics.median(per_run), 4)}


def both_models(site: str, browser) -> dict:
    """Chapter 05's box in a fresh page: what asking both PGAE-BERT models about one sentence fetches, in all
    (the runtime and both models too) and for free text alone."""
    context = browser.new_context()
    context.route("**/*", lambda r: r.continue_() if r.request.url.startswith(site) else r.abort())
    page, received = context.new_page(), []
    page.goto(f"{site}/notebooks/05_pgae_bert.html", wait_until="load")
    page.evaluate("window.pgae.load()")
    page.on("response", lambda r: received.append((r.url, body_size(r))))
    t = time.perf_counter()
    page.locator(".pgae-understood button").first.click()
    page.wait_for_function("document.querySelector('.pgae-understood').dataset.done === '1'", timeout=120_000)
    seconds = time.perf_counter() - t
    page.wait_for_timeout(200)
    context.close()
    return {"bytes": sum(n for _, n in received), "seconds": round(seconds, 3),
            "free_text_bytes": sum(n for url, n in received if any(part in url for part in FREE))}


def parity(site: str, browser, name: str, manifest: dict, per_kind: int, profile) -> dict:
    """Free text in the page against Python: every paraphrase, each on a test episode with its cube, and
    ``per_kind`` sentences of each kind of the refusal grammar (pgae_lite.freeform.refusal_grammar), each on
    a random test episode.
    Python's refusal refuses a text or not; the page must refuse it with the same sentence, or give the
    same words and readback, and joints within float16 rounding. ``profile``: the Profile the page was exported
    with (its name is the manifest's)."""
    import random

    import numpy as np

    from pgae_lite.freeform.refusal_grammar import CLASSES, sentence
    from pgae_lite.freeform.refusals import refusal
    from pgae_lite.runs.data import simulated_dataset
    from pgae_lite.runs.pipeline import trained_model
    from pgae_lite.web.sentence import free_text_reference

    assert manifest["profile"] == profile.name, (manifest["profile"], profile.name)
    seed = manifest["seed"]
    run = trained_model(MODELS[name], profile, seed, device="cpu", progress=False)
    test = simulated_dataset(profile, "cpu", progress=False).split("test")
    scenes = [tuple(e["scene"]) for e in manifest["episodes"] if e["split"] == "test"]   # the test split's order
    texts, rows, rng = [], [], random.Random(seed)
    for p in load_paraphrases():
        texts.append(p.text)
        rows.append(next((k for k, scene in enumerate(scenes) if p.colour in scene), 0))
    for kind in CLASSES:
        for _ in range(per_kind):
            rows.append(rng.randrange(len(test)))
            texts.append(sentence(kind, scenes[rows[-1]], rng))
    want = free_text_reference(run.model, run.normaliser, test, texts, rows)
    context = browser.new_context()
    context.route("**/*", lambda r: r.continue_() if r.request.url.startswith(site) else r.abort())
    page = context.new_page()
    page.goto(f"{site}/notebooks/08_playground.html", wait_until="domcontentloaded")
    got = page.evaluate("""async ([model, texts, ids]) => {
        const out = [];
        for (let i = 0; i < texts.length; i++) {
          try { out.push(await window.pgae.run({model, signal: "execute", episode: ids[i], text: texts[i],
                                                route: "direct"})); }
          catch (e) { out.push({refused: e.message}); }
        }
        return out; }""", [name, texts, [w["episode"] for w in want]])
    context.close()
    span = float(run.normaliser.joints[1] - run.normaliser.joints[0])
    refused, differ, joints = 0, [], 0.0
    for text, r, w, row in zip(texts, got, want, rows):
        why = refusal(text, run.model.language_encoder, scenes[row], w["understood"])
        refused += why is not None
        if why or "refused" in r:
            differ += [] if r == {"refused": why} else [text]
        elif (r["words"], r["understood"]) != (w["words"], w["understood"]):
            differ.append(text)
        else:
            joints = max(joints, float(np.abs(np.array(r["joints"]) - w["joints"]).max()) / span)
    return {"model": name, "sentences": len(texts), "paraphrases": len(load_paraphrases()),
            "grammar_sentences_per_kind": per_kind, "refused_by_python": refused, "differ": len(differ),
            "differing": differ, "max_joint_difference_of_range": joints}


def main() -> None:
    bench = Benchmark("live_playground", __doc__)
    bench.parser.add_argument("--book", default=str(ROOT / "_build" / "html"), help="the built book")
    bench.parser.add_argument("--runs", type=int, default=20, help="runs timed after the first, per model")
    bench.parser.add_argument("--per-kind", type=int, default=20,
                              help="sentences of each kind of the refusal grammar in the free-text parity")
    args = bench.parse()
    from playwright.sync_api import sync_playwright

    from pgae_lite.config import get_profile

    profile = get_profile(args.profile)                      # resolved once, here

    with tempfile.TemporaryDirectory() as tmp:
        site_dir = Path(tmp) / "html"
        shutil.copytree(args.book, site_dir)
        shutil.rmtree(site_dir / "_static" / "web", ignore_errors=True)
        manifest = export_web(site_dir / "_static" / "web", profile, args.seeds[0])
        static = site_dir / "_static"
        files = {p.relative_to(static).as_posix(): p.stat().st_size
                 for folder in ("web", "ort", "tokenizers") for p in (static / folder).rglob("*") if p.is_file()}
        site, server = serve(site_dir)
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_FLAGS)
            models = [measure(site, browser, name, args.runs) for name in manifest["models"]]
            box = both_models(site, browser)
            free = [parity(site, browser, name, manifest, args.per_kind, profile)
                    for name, m in manifest["models"].items() if m["reads"] == "features"]
            browser.close()
        server.shutdown()
        # the same parity with the sentence encoder's weights in float32 (export-web --float32): what float16 costs
        shutil.rmtree(site_dir / "_static" / "web")
        full = export_web(site_dir / "_static" / "web", profile, args.seeds[0], simulate=False, half=False)
        site, server = serve(site_dir)
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_FLAGS)
            free32 = [parity(site, browser, name, full, args.per_kind, profile)
                      for name, m in full["models"].items() if m["reads"] == "features"]
            browser.close()
        server.shutdown()
    for m in models:
        print(m, flush=True)
    for m in free + free32:
        print(m, flush=True)
    print("chapter 05's box, both models:", box, flush=True)
    vendored = {json.loads((ROOT / "book" / "_vendor" / d / "package.json").read_text())["name"]:
                json.loads((ROOT / "book" / "_vendor" / d / "package.json").read_text())["version"]
                for d in ("ort", "tokenizers")}
    within = (all(m["seconds_to_first_result"] <= 3.0 and m["live_bytes"] <= 20e6
                  and m.get("free_text_bytes", 0) <= 50e6 for m in models) and box["free_text_bytes"] <= 50e6)
    bench.write({"models": models, "free_text_parity": free, "chapter05_box_both_models": box, "files": files,
                 "free_text_parity_float32": free32, "free_text_megabytes_float32": full["free_text"]["bytes"] / 1e6,
                 "episodes": len(manifest["episodes"]),
                 "episodes_by_split": {split: sum(e["split"] == split for e in manifest["episodes"])
                                       for split in ("test", "train")},
                 "transformer_weights": "float16", "vendored": vendored,
                 "budget": {"seconds_to_first_result": 3.0, "live_megabytes": 20.0, "free_text_megabytes": 50.0},
                 "within_budget": within})

if __name__ == "__main__":
    main()
