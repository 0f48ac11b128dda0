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

from browser_support import CHROMIUM, offline_page  # noqa: E402

from pgae_lite.model.signals import make_batch, signal_ids  # noqa: E402
from pgae_lite.world.words import TEST_SIGNALS, LanguageError, decode  # noqa: E402

MANIFEST = json.loads((BOOK / "_static" / "web" / "manifest.json").read_text(encoding="utf-8"))
PAGE = "notebooks/08_playground.html"


@pytest.fixture(scope="module")
def page():
    if not Path(CHROMIUM).exists():
        pytest.skip(f"no Chromium at {CHROMIUM}")
    with offline_page(BOOK, PAGE) as opened:
        yield opened


def _python(name: str):
    """The PyTorch model the page's graph was exported from, its normaliser and the test split."""
    from pgae_lite.config import get_profile
    from pgae_lite.runs.data import simulated_dataset
    from pgae_lite.runs.pipeline import trained_model
    from pgae_lite.web.assets import MODELS

    profile = get_profile(MANIFEST["profile"])                         # the page's profile, resolved here
    run = trained_model(MODELS[name], profile, MANIFEST["seed"], device="cpu", progress=False)
    return run.model.eval(), run.normaliser, simulated_dataset(profile, "cpu", progress=False).split("test")


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


def test_a_typed_description_picks_its_episode_and_is_said_back_as_play_does(page):
    """A description typed for PGAE picks the action it names in the chosen scene, as play() does; one naming
    a cube that is not on the table is refused with play()'s sentence."""
    from pgae_lite.config import get_profile
    from pgae_lite.robot.playground import play
    from pgae_lite.runs.data import simulated_dataset

    pg, _ = page
    ask = """async (args) => { try { return await window.pgae.run(args); } catch (e) { return e.message; } }"""
    model, normaliser, _ = _python("PGAE")
    data = simulated_dataset(get_profile(MANIFEST["profile"]), "cpu", progress=False)
    episode = MANIFEST["episodes"][0]
    left, right = episode["scene"]
    absent = next(c for c in ("red", "green", "blue", "yellow", "violet", "cyan") if c not in (left, right))
    place = {"arrangement": episode["arrangement"], "action": episode["action"]}
    for text in (f"Move Up {right}, quickly", f"pull {left} slowly", f"push {absent} fast"):
        got = pg.evaluate(ask, {"model": "PGAE", "signal": "execute", **place, "text": text})
        try:
            want = play(model, None, normaliser, data, "execute", text=text, loop=None, **place)
        except ValueError as e:
            assert got == str(e), text
            continue
        assert (got["episode"], got["words"], got["understood"]) == (want.episode, want.words, want.understood), text


@pytest.mark.parametrize("args, typed", [
    ({"signal": "execute", "text": "push the red cube"}, ("PGAE", "execute", "push the red cube")),
    ({"signal": "execute", "text": "red push fast"}, ("PGAE", "execute", "red push fast")),
    ({"signal": "execute", "text": "push red"}, ("PGAE", "execute", "push red")),
    ({"signal": "execute", "text": "please push the red block away"},
     ("PGAE", "execute", "please push the red block away")),
    ({"model": "PGAE-BERT", "signal": "describe", "text": "push it"}, ("PGAE-BERT", "describe", "push it")),
])
def test_bad_input_gets_the_sentence_python_gives(page, args, typed):
    """The sentence Python's play() gives for a typed text (read_typed), word for word."""
    from pgae_lite.robot.typed_text import read_typed

    pg, _ = page
    model, signal, text = typed
    with pytest.raises(LanguageError) as expected:
        read_typed(_python(model)[0].language_encoder, signal, text)
    message = pg.evaluate("""async (args) => {
        try { await window.pgae.run(args); return null; } catch (e) { return e.message; } }""",
                          {"model": "PGAE", "episode": MANIFEST["episodes"][0]["id"], **args})
    assert message == str(expected.value)


FREE_MODELS = [name for name, m in MANIFEST["models"].items() if m["reads"] == "features"]
# Unknown words for the variant's lookup, spelled and cased as a reader might type them
TYPED = ["slide the amethyst cube aside", "Drag the CRIMSON block toward you hastily", "nudge teal forward, gently",
         "push the scarlet-ish one?"]


def _texts() -> list[str]:
    from pgae_lite.freeform.paraphrases import load_paraphrases

    return [p.text for p in load_paraphrases()] + TYPED


def _page_runs(pg, name: str, texts: list[str], episodes: list[str]) -> list[dict]:
    """Each text run in the page under execute on its episode: the result and the text as read, or the
    sentence it was refused with."""
    return pg.evaluate("""async ([model, texts, ids]) => {
        const out = [];
        for (let i = 0; i < texts.length; i++) {
          try {
            const r = await window.pgae.run({model, signal: "execute", episode: ids[i], text: texts[i],
                                             route: "direct"});
            out.push({...r, read: await window.pgae.readAs(model, texts[i])});
          } catch (e) { out.push({refused: e.message}); }
        }
        return out; }""", [name, texts, episodes])


@pytest.mark.parametrize("name", FREE_MODELS)
def test_free_text_in_the_page_is_what_pytorch_computes(page, name):
    """Every free-form sentence of the project, each on a test episode with its cube where one exists:
    what the page writes and says back is PyTorch's, the text is read as Python reads it, the joints are
    within 1e-3 of the joint range (the page's transformer has float16 weights), and a text Python's
    refusal refuses is refused with its sentence."""
    from pgae_lite.freeform.paraphrases import load_paraphrases
    from pgae_lite.freeform.refusals import refusal
    from pgae_lite.web.sentence import free_text_reference

    pg, errors = page
    model, normaliser, test = _python(name)
    texts, span = _texts(), float(normaliser.joints[1] - normaliser.joints[0])
    scenes = [MANIFEST["episodes"][i]["scene"] for i in range(len(test))]
    colours = [p.colour for p in load_paraphrases()] + [None] * len(TYPED)
    rows = [next((k for k, scene in enumerate(scenes) if c in scene), i % len(test)) for i, c in enumerate(colours)]
    want = free_text_reference(model, normaliser, test, texts, rows)
    got = _page_runs(pg, name, texts, [w["episode"] for w in want])
    acted = 0
    for text, r, w, row in zip(texts, got, want, rows):
        why = refusal(text, model.language_encoder, tuple(scenes[row]), w["understood"])
        if why:
            assert r == {"refused": why}, text
            continue
        acted += 1
        assert r["read"] == model.language_encoder.read_as(text), text
        assert (r["words"], r["understood"]) == (w["words"], w["understood"]), text
        assert np.abs(np.array(r["joints"]) - w["joints"]).max() <= 1e-3 * span, text
    assert acted >= len(texts) // 2, acted
    assert not errors, errors


def test_unknown_model_signal_and_episode_are_refused(page):
    pg, _ = page
    ask = """async (args) => { try { await window.pgae.run(args); return null; } catch (e) { return e.message; } }"""
    episode = MANIFEST["episodes"][0]["id"]
    assert "unknown model 'GPT'" in pg.evaluate(ask, {"model": "GPT", "signal": "execute", "episode": episode})
    assert pg.evaluate(ask, {"model": "PGAE", "signal": "dance", "episode": episode}) == (
        "unknown signal 'dance'; the signals are: describe, execute, repeat action, repeat both, repeat language")
    assert "no episode 'sim/999-9' in this page" in pg.evaluate(ask, {"model": "PGAE", "signal": "execute",
                                                                     "episode": "sim/999-9"})


def test_the_widget_runs_in_the_page(page):
    pg, errors = page
    widget = pg.locator(".pgae-live").first
    widget.locator("button").click()
    pg.wait_for_function("document.querySelector('.pgae-live').dataset.result !== undefined")
    result = json.loads(widget.get_attribute("data-result"))
    assert len(result["joints"]) == MANIFEST["episodes"][0]["steps"] and len(result["gate"]) > 0
    assert "computed in this page" in widget.locator("pre").inner_text()
    shown = widget.locator(".pgae-live-camera img")              # NICO's recorded camera, loaded
    assert shown.count() == 2 and all(shown.nth(k).evaluate("i => i.complete && i.naturalWidth") == 160
                                      for k in range(2))
    # the arm at the episode's last step (the animation stopped there), as a reader sees it after Play
    widget.locator("input.pgae-live-time").evaluate("s => { s.value = s.max; s.dispatchEvent(new Event('input')); }")
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


def test_the_simulators_runs_are_shown_labelled(page):
    pg, errors = page
    if not MANIFEST["sim_runs"]:
        pytest.skip("built without the simulator's runs")
    episode = MANIFEST["episodes"][0]
    run = pg.evaluate("([e]) => window.pgae.simulated('PGAE', e)", [episode["id"]])
    assert run["label"].startswith("Run in the pybullet simulator when this book was built")
    assert len(run["cubes"]) == len(run["joints"]) == episode["steps"] and run["kind"] == "closed loop"
    assert np.allclose(np.array(run["cubes"])[0, :, :2], episode["cubes"], atol=1e-4)   # where the recording had them
    assert pg.evaluate("window.pgae.simulated('PGAE', 'sim/999-9')") is None
    widget = pg.locator(".pgae-live").first                    # execute on that episode: the label is shown
    widget.locator("button").click()
    pg.wait_for_function("document.querySelector('.pgae-live').dataset.result !== undefined")
    assert run["label"] in widget.locator(".pgae-live-cubes").inner_text()
    assert not errors, errors


def test_chapter_05s_box_says_what_both_models_understood(page):
    """The box on chapter 05 runs both PGAE-BERT models in the page and shows what run() says back."""
    pg, errors = page
    pg.goto(pg.url.replace(PAGE, "notebooks/05_pgae_bert.html"), wait_until="load")
    box = pg.locator(".pgae-understood").first
    text = "could you drag the amethyst block towards you, quickly"
    box.locator("input").fill(text)
    box.locator("button").click()
    pg.wait_for_function("document.querySelector('.pgae-understood').dataset.done === '1'")
    said = box.locator("pre").inner_text()
    episode = MANIFEST["episodes"][0]["id"]
    for name in FREE_MODELS:
        r = pg.evaluate("([model, episode, text]) => window.pgae.run({model, signal: 'repeat language', episode, "
                        "text})", [name, episode, text])
        assert f"{name} understood: {r['understood']}" in said, said
    box.screenshot(path=str(ROOT / "_build" / "screenshots" / "chapter05_understood.png"))
    pg.goto(pg.url.replace("notebooks/05_pgae_bert.html", PAGE), wait_until="load")
    assert not errors, errors


# Instructions the robot may refuse, of each kind the rule knows (and some it acts on)
INSTRUCTIONS = ["don't push the red cube", "please never pull the blue block", "stop sliding it",
                "push the red cube and then pull it back", "shove it, then drag it toward you",
                "slide the red one and the blue one", "push it slowly, no, fast", "push the black cube away",
                "drag the orange block over", "rotate the red cube", "lift it up", "spin the block around",
                "push the green cube away", "pull the violet one quickly", "nudge the crimson block forward",
                "please push it away, no rush", "haul the cube towards you in a hurry", "do it"]


@pytest.mark.parametrize("name", FREE_MODELS)
def test_the_page_refuses_what_python_refuses(page, name):
    """Under execute, free text gets the sentence Python's refusal gives (CannotDo), or acts with its note."""
    from pgae_lite.freeform.paraphrases import load_paraphrases
    from pgae_lite.freeform.refusals import disagreement, refusal
    from pgae_lite.web.sentence import free_text_reference

    pg, errors = page
    model, normaliser, test = _python(name)
    texts = INSTRUCTIONS + [p.text for p in load_paraphrases()[::9]]
    want = free_text_reference(model, normaliser, test, texts)
    episodes = {e["id"]: e for e in MANIFEST["episodes"]}
    got = [r.get("note") if "refused" not in r else f"refused: {r['refused']}"
           for r in _page_runs(pg, name, texts, [w["episode"] for w in want])]
    refused = 0
    for text, w, r in zip(texts, want, got):
        ep = episodes[w["episode"]]
        why = refusal(text, model.language_encoder, tuple(ep["scene"]), w["understood"])
        refused += why is not None
        assert r == (f"refused: {why}" if why else disagreement(w["understood"], ep["pattern"])), text
    assert refused >= len(INSTRUCTIONS) // 2                  # the rule ran: most of these are refused
    assert not errors, errors


def _in_widget(pg, choices: dict[str, str]) -> dict | str:
    """Set the widget's controls by their names (a select's value, or the text) and press Run: the result it
    stored, or the message it shows instead."""
    widget = pg.locator(".pgae-live").first
    widget.evaluate("w => { delete w.dataset.result; }")
    for name, value in choices.items():
        control = widget.locator(f"[aria-label='{name}']").first
        if name == "text":
            control.fill(value)
        else:
            control.select_option(value)
            control.dispatch_event("change")
    widget.locator("button.pgae-live-run").click()
    pg.wait_for_function("""() => { const w = document.querySelector('.pgae-live');
        return w.dataset.result !== undefined || !w.querySelector('.pgae-live-error').hidden; }""", timeout=120_000)
    stored = widget.get_attribute("data-result")
    return json.loads(stored) if stored else widget.locator(".pgae-live-error").inner_text()


@pytest.mark.parametrize("width", [1280, 390])
def test_the_widget_refuses_says_back_picks_and_says_how_sure_on_a_phone_too(page, width):
    """The four things a reader does with the live box, at a desktop's and a phone's width: a refused
    instruction (the drawing hidden, the page's sentence shown), a said-back execution, a typed description
    that picks its episode, and nonsense with how sure the decoder was; screenshots of each."""
    pg, errors = page
    pg.set_viewport_size({"width": width, "height": 900})
    widget, shots = pg.locator(".pgae-live").first, ROOT / "_build" / "screenshots"
    shots.mkdir(parents=True, exist_ok=True)
    free = [name for name in FREE_MODELS if MANIFEST["models"][name]["route"] == "said back"]
    first = MANIFEST["episodes"][0]
    left, right = first["scene"]
    place = {"cubes": str(first["arrangement"]), "action": str(first["action"]), "variation": "0"}
    cases = {"refused": {"model": free[0], "signal": "execute", **place, "text": f"don't push the {left} cube"},
             "said-back": {"model": free[0], "signal": "execute", **place, "act on": "said back",
                           "text": f"please push the {left} cube slowly"},
             "description": {"model": "PGAE", "signal": "execute", **place, "text": f"pull {right} fast"},
             "nonsense": {"model": FREE_MODELS[0], "signal": "repeat language", **place, "text": "blorp fizz wug"}}
    got, shown = {}, {}
    for name, choices in cases.items():
        got[name] = _in_widget(pg, choices)
        widget.screenshot(path=str(shots / f"live-{name}-{width}px.png"))
        assert pg.evaluate("document.documentElement.scrollWidth") <= width + 1, (name, width)
        assert widget.locator(".pgae-live-result").is_hidden() == isinstance(got[name], str), name   # none stale
        shown[name] = widget.inner_text()
    assert got["refused"].startswith("Cannot run this: I can't do") and "what not to do" in got["refused"]
    assert got["said-back"]["route"] == "said back" and got["said-back"]["acted_on"] is not None
    assert f"acted on (said back): {got['said-back']['acted_on']!r}" in shown["said-back"]
    asked = got["description"]
    assert asked["pattern"] != first["pattern"] and asked["episode"].startswith(f"sim/{asked['pattern']:03d}-")
    nonsense = got["nonsense"]
    assert nonsense["understood_choices"] and widget.locator("table.pgae-live-choices").count() >= 1
    assert f"{nonsense['understood_choices'][0]['p']:.2f}" in shown["nonsense"]       # how sure, as a number
    pg.set_viewport_size({"width": 1280, "height": 900})
    assert not errors, errors
