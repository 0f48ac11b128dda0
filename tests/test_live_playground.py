"""The live playground in a real headless browser: the page's results equal PyTorch's.

The built book (``_build/html``, with ``_static/web`` from ``book/_ext/live_models.py``) is served
from localhost with every other request aborted. ``window.pgae.run`` (``book/_js/pgae.js``) runs
each model of the playground on every test episode under every signal, in onnxruntime-web; the
same inputs go through the PyTorch model here: the words must be identical, the joints within
1e-4 of the joint range, the gate within 1e-4. Bad arguments reject with Python's sentence. The
widget in chapter 08 runs too. Skipped like tests/test_book_browser.py when there is no built
book or no browser.
"""
from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest
import torch

ROOT = Path(__file__).resolve().parents[1]
BOOK = Path(os.environ.get("PGAE_LIVE_SITE", ROOT / "_build" / "html"))
if not (BOOK / "_static" / "web" / "manifest.json").exists():
    pytest.skip(f"no live playground in {BOOK}: build the book first", allow_module_level=True)

from browser_support import CHROMIUM, CHROMIUM_FLAGS, KNOWN_CONSOLE_ERRORS, serve  # noqa: E402

from pgae_lite.model.signals import make_batch, signal_ids  # noqa: E402
from pgae_lite.world.words import TEST_SIGNALS, LanguageError, decode, parse_description  # noqa: E402

MANIFEST = json.loads((BOOK / "_static" / "web" / "manifest.json").read_text(encoding="utf-8"))
PAGE = "notebooks/08_playground.html"


@pytest.fixture(scope="module")
def page():
    if not Path(CHROMIUM).exists():
        pytest.skip(f"no Chromium at {CHROMIUM}")
    from playwright.sync_api import sync_playwright

    site, server = serve(BOOK)
    errors = []
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_FLAGS)
        context = browser.new_context()
        context.route("**/*", lambda r: r.continue_() if r.request.url.startswith(site) else r.abort())
        pg = context.new_page()
        pg.on("console", lambda m: m.type == "error" and not any(k.search(m.text) for k in KNOWN_CONSOLE_ERRORS)
              and errors.append(m.text))
        pg.on("pageerror", lambda e: not any(k.search(str(e)) for k in KNOWN_CONSOLE_ERRORS) and errors.append(str(e)))
        pg.goto(f"{site}/{PAGE}", wait_until="load")
        pg.evaluate("window.pgae.load()")
        yield pg, errors
        browser.close()
    server.shutdown()


def _python(name: str):
    """The PyTorch model the page's graph was exported from, its normaliser and the test split."""
    from pgae_lite.runs.pipeline import simulated_dataset, trained_pgae
    from pgae_lite.web.assets import MODELS

    run = trained_pgae(MODELS[name], MANIFEST["profile"], MANIFEST["seed"], device="cpu", progress=False)
    return run.model.eval(), run.normaliser, simulated_dataset(MANIFEST["profile"], "cpu", progress=False).split("test")


@pytest.mark.parametrize("name", list(MANIFEST["models"]))
def test_the_page_computes_what_pytorch_computes(page, name):
    pg, errors = page
    model, normaliser, test = _python(name)
    tensors, n = normaliser.tensors(test), len(test)
    span = float(normaliser.joints[1] - normaliser.joints[0])
    for signal in TEST_SIGNALS:
        batch = make_batch(tensors, torch.arange(n), signal_ids(signal, n), torch.zeros(n, dtype=torch.long))
        with torch.no_grad():
            out = model(batch)
        got = pg.evaluate("""async ([model, signal, ids]) => {
            const out = [];
            for (const episode of ids) out.push(await window.pgae.run({model, signal, episode}));
            return out; }""", [name, signal, [str(i) for i in test.ids]])
        for i, r in enumerate(got):
            steps = int(test.lengths[i])
            joints = normaliser.joints_to_data(torch.cat([batch.start_joints[i:i + 1], out["joints"][i]]))[:steps]
            assert r["words"] == decode(out["logits"][i].argmax(-1)), (name, signal, test.ids[i])
            assert np.abs(np.array(r["joints"]) - joints.numpy()).max() <= 1e-4 * span, (name, signal, test.ids[i])
            assert np.abs(np.array(r["gate"]) - out["gate"][i].numpy()).max() <= 1e-4
    assert not errors, errors


def test_a_typed_description_is_read_and_said_back(page):
    from pgae_lite.world.words import WORD_INDEX, tokenize

    pg, _ = page
    text, episode = "Move Up blonde, quickly", MANIFEST["episodes"][0]["id"]
    r = pg.evaluate("([text, episode]) => window.pgae.run({model: 'PGAE', signal: 'execute', episode, text})",
                    [text, episode])
    model, normaliser, test = _python("PGAE")
    tensors = normaliser.tensors(test.subset([list(map(str, test.ids)).index(episode)]))
    tensors["descriptions"][:] = torch.tensor([WORD_INDEX[w] for w in tokenize(text)])   # as play() does
    said = {}
    for signal in ("execute", "repeat language"):
        with torch.no_grad():
            out = model(make_batch(tensors, torch.zeros(1, dtype=torch.long), signal_ids(signal, 1),
                                   torch.zeros(1, dtype=torch.long)))
        said[signal] = decode(out["logits"][0].argmax(-1))
    assert (r["words"], r["understood"]) == (said["execute"], said["repeat language"])


@pytest.mark.parametrize("args, python", [
    ({"signal": "execute", "text": "push the red cube"}, lambda: parse_description("push the red cube")),
    ({"signal": "execute", "text": "red push fast"}, lambda: parse_description("red push fast")),
    ({"signal": "execute", "text": "push red"}, lambda: parse_description("push red")),
])
def test_bad_input_gets_the_sentence_python_gives(page, args, python):
    pg, _ = page
    with pytest.raises(LanguageError) as expected:
        python()
    message = pg.evaluate("""async (args) => {
        try { await window.pgae.run(args); return null; } catch (e) { return e.message; } }""",
                          {"model": "PGAE", "episode": MANIFEST["episodes"][0]["id"], **args})
    assert message == str(expected.value)


def test_free_text_for_pgae_bert_says_the_page_reads_descriptions_only(page):
    pg, _ = page
    message = pg.evaluate("""async (args) => {
        try { await window.pgae.run(args); return null; } catch (e) { return e.message; } }""",
                          {"model": "PGAE-BERT", "signal": "execute", "episode": MANIFEST["episodes"][0]["id"],
                           "text": "please push the red block away"})
    assert message.startswith("PGAE-BERT reads any sentence in Python") and "descriptions only" in message


def test_unknown_model_signal_and_episode_are_refused(page):
    pg, _ = page
    ask = """async (args) => { try { await window.pgae.run(args); return null; } catch (e) { return e.message; } }"""
    episode = MANIFEST["episodes"][0]["id"]
    assert "unknown model 'GPT'" in pg.evaluate(ask, {"model": "GPT", "signal": "execute", "episode": episode})
    assert pg.evaluate(ask, {"model": "PGAE", "signal": "dance", "episode": episode}) == (
        "unknown signal 'dance'; the signals are: describe, execute, repeat action, repeat both, repeat language")
    assert "no test episode 'sim/999-9'" in pg.evaluate(ask, {"model": "PGAE", "signal": "execute",
                                                             "episode": "sim/999-9"})


def test_the_widget_runs_in_the_page(page):
    pg, errors = page
    widget = pg.locator(".pgae-live").first
    widget.locator("button").click()
    pg.wait_for_function("document.querySelector('.pgae-live').dataset.result !== undefined")
    result = json.loads(widget.get_attribute("data-result"))
    assert len(result["joints"]) == MANIFEST["episodes"][0]["steps"] and len(result["gate"]) > 0
    assert "computed in this page" in widget.locator("pre").inner_text()
    Path(ROOT / "_build" / "screenshots").mkdir(parents=True, exist_ok=True)
    widget.screenshot(path=str(ROOT / "_build" / "screenshots" / "live_playground.png"))
    assert not errors, errors


def test_the_pages_forward_kinematics_is_the_simulators(page):
    from pgae_lite.sim.record import scene_layout
    from pgae_lite.sim.robot import JOINT_LIMITS
    from pgae_lite.sim.scene import Scene

    pg, _ = page
    rng = np.random.default_rng(0)
    poses = [[float(rng.uniform(lo, hi)) for lo, hi in JOINT_LIMITS] for _ in range(8)]
    tips = pg.evaluate("(poses) => poses.map(q => window.pgae.fk(q)[3])", poses)
    scene = Scene(scene_layout(0))
    try:
        for q, tip in zip(poses, tips):
            assert np.abs(np.array(tip) - scene.nico.forward_kinematics(np.array(q))).max() < 1e-5, q
    finally:
        scene.close()
    episode = MANIFEST["episodes"][0]
    layout = scene_layout(episode["pattern"], int(episode["id"].rsplit("-", 1)[1]))
    assert np.allclose(episode["cubes"], [layout.left_xy, layout.right_xy])
