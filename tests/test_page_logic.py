"""The live playground's JavaScript is `play`: its answers against Python's, in a headless browser, no book build.

``export_web`` writes the smoke profile's playground (ONNX models, episodes, manifest and
``parity.json``, Python's answers to the page's inputs: pgae_lite/web/parity.py) into a temporary
folder, beside the page's scripts (book/_js) and the vendored runtime (book/_vendor/ort,
tokenizers). A one-line page loads the scripts in Debian's Chromium, offline, and every vector is
run through the page's own functions: how it quotes text, reads a typed text, builds a signal's
inputs, reads a text through the variant's word lookup, refuses what the robot will not do, how
sure it says the decoder was, and, end to end, ``window.pgae.run`` against ``play`` (words,
readback, note, route, verdict, episode, joints). Skipped without Chromium or Playwright, as the
other browser tests (unless PGAE_BROWSER_REQUIRED=1).
"""
from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import numpy as np
import pytest
from browser_support import CHROMIUM, offline_page

ROOT = Path(__file__).resolve().parents[1]
PAGE = """<!doctype html><meta charset="utf-8"><title>page logic</title>
<script src="_static/pgae-logic.js"></script><script src="_static/pgae-arm.js"></script>
<script src="_static/pgae.js"></script>"""
TOLERANCE = 1e-4          # of the joint range: float32 in onnxruntime-web against PyTorch


def _browser_or_skip():
    required = os.environ.get("PGAE_BROWSER_REQUIRED") == "1"
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError:
        if required:
            raise
        pytest.skip("Playwright is not installed")
    if not Path(CHROMIUM).exists():
        if required:
            raise FileNotFoundError(f"no Chromium at {CHROMIUM}")
        pytest.skip(f"no Chromium at {CHROMIUM}")


@pytest.fixture(scope="module")
def site(tmp_path_factory, smoke_episodes):
    """The smoke playground and the page's scripts in a temporary folder: (folder, parity vectors)."""
    from pgae_lite.config import get_profile
    from pgae_lite.web.assets import export_web

    _browser_or_skip()
    folder = tmp_path_factory.mktemp("page")
    static = folder / "_static"
    made = os.environ.get("PGAE_PAGE_EXPORT")         # a folder export_web wrote before (to run the test again)
    if made:
        shutil.copytree(made, static / "web")
    else:
        export_web(static / "web", get_profile("smoke"), simulate=False)
    for script in (ROOT / "book" / "_js").glob("pgae*.js"):
        shutil.copy(script, static / script.name)
    for vendored in ("ort", "tokenizers"):
        shutil.copytree(ROOT / "book" / "_vendor" / vendored, static / vendored)
    (folder / "index.html").write_text(PAGE, encoding="utf-8")
    return folder, json.loads((static / "web" / "parity.json").read_text(encoding="utf-8"))


@pytest.fixture(scope="module")
def page(site):
    folder, vectors = site
    with offline_page(folder, "index.html") as (pg, errors):
        yield pg, vectors, errors


def _in_page(pg, script: str, vectors: list):
    """``script`` (a JS function of one vector, which may return a promise) on every vector: its value, or
    {"error": message} where it threw."""
    return pg.evaluate("""async ([body, vectors]) => {
        const L = window.pgae.logic(), f = eval(body), out = [];
        for (const v of vectors) {
            try { out.push({value: await f(v, L)}); } catch (e) { out.push({error: e.message}); }
        }
        return out;
    }""", [script, vectors])


def test_the_page_quotes_text_as_python_does(page):
    pg, vectors, errors = page
    got = _in_page(pg, "([text]) => window.pgaeLogic.pyrepr(text)", vectors["repr"])
    wrong = [(text, want, g) for (text, want), g in zip(vectors["repr"], got) if g.get("value") != want]
    assert not wrong, wrong
    assert not errors


def test_a_typed_text_is_read_as_python_reads_it(page):
    pg, vectors, _ = page
    got = _in_page(pg, """(v, L) => L.readTyped(window.pgae.manifest().models[v.model], v.signal, v.text)""",
                   vectors["typed"])
    for v, g in zip(vectors["typed"], got):
        if v["error"]:
            assert g.get("error") == v["error"], v
        else:
            assert g.get("value", {}).get("words") == v["words"] and g["value"]["meaning"] == v["meaning"], (v, g)


def test_each_signals_inputs_are_the_batch_python_builds(page):
    pg, vectors, _ = page
    got = _in_page(pg, """async (v, L) => {
        const m = window.pgae.manifest(), ep = m.episodes.find(e => e.id === v.episode);
        const values = new Float32Array(await (await fetch("_static/web/" + m.episodes_files[ep.split])).arrayBuffer());
        const x = L.inputs(ep, values, m.signals.indexOf(v.signal), v.words);
        return {tokens: x.tokens, shown: x.shown, dec: Array.from(x.dec), start: Array.from(x.start)};
    }""", vectors["batches"])
    for v, g in zip(vectors["batches"], got):
        x = g["value"]
        assert x["tokens"] == v["tokens"] and x["shown"] == v["action_steps"], (v["episode"], v["signal"], x["tokens"])
        assert np.array_equal(np.float32(x["dec"]), np.float32(v["dec"])), (v["episode"], v["signal"])
        assert np.array_equal(np.float32(x["start"]), np.float32(v["start"])), (v["episode"], v["signal"])


def test_the_variants_lookup_reads_each_word_as_python_does(page):
    pg, vectors, _ = page
    got = _in_page(pg, """async (v) => ({read: await window.pgae.readAs(v.model, v.text),
                                         swapped: await window.pgae.replacements(v.model, v.text)})""",
                   vectors["readings"])
    wrong = [(v["model"], v["text"], v["read"], g) for v, g in zip(vectors["readings"], got)
             if g.get("value") != {"read": v["read"], "swapped": v["replacements"]}]
    assert not wrong, wrong[:5]


def test_the_page_refuses_what_python_refuses_with_its_sentence(page):
    pg, vectors, _ = page
    got = _in_page(pg, "(v) => window.pgae.refusal(v.model, v.text, v.scene, v.understood)", vectors["refusals"])
    wrong = [(v["model"], v["text"], v["scene"], v["message"], g) for v, g in zip(vectors["refusals"], got)
             if g.get("value") != v["message"]]
    assert len(vectors["refusals"]) > 300
    assert not wrong, f"{len(wrong)} of {len(got)} differ, e.g. {wrong[:3]}"


def test_how_sure_the_decoder_was_is_computed_as_in_python(page):
    pg, vectors, _ = page
    got = _in_page(pg, "(v, L) => L.choices(v.logits.flat())", vectors["choices"])
    for v, g in zip(vectors["choices"], got):
        assert [c["word"] for c in g["value"]] == [c["word"] for c in v["choices"]]
        assert [c["runner_up"] for c in g["value"]] == [c["runner_up"] for c in v["choices"]]
        assert np.allclose([c["p"] for c in g["value"]], [c["p"] for c in v["choices"]], atol=1e-6)


EXACT = ("signal", "pattern", "variation", "episode", "told", "words", "correct", "understood", "note", "route",
         "acted_on")


def test_run_is_play(page):
    pg, vectors, errors = page
    span = float(np.ptp(np.concatenate([np.asarray(v["result"]["joints"]) for v in vectors["plays"]
                                        if v["result"]])))
    got = _in_page(pg, "(v) => window.pgae.run({model: v.model, ...v.args})", vectors["plays"])
    for v, g in zip(vectors["plays"], got):
        where = (v["model"], v["args"])
        if v["error"]:
            assert g.get("error") == v["error"], where
            continue
        assert "value" in g, (where, g)
        page_result, python = g["value"], v["result"]
        assert {k: page_result[k] for k in EXACT} == {k: python[k] for k in EXACT}, where
        for key in ("choices", "understood_choices"):
            if python[key] is None:
                assert page_result[key] is None, where
                continue
            assert [c["word"] for c in page_result[key]] == [c["word"] for c in python[key]], where
            assert np.allclose([c["p"] for c in page_result[key]], [c["p"] for c in python[key]], atol=1e-3), where
        for key in ("joints", "target"):
            assert np.abs(np.asarray(page_result[key]) - np.asarray(python[key])).max() <= TOLERANCE * span, where
        assert abs(page_result["nrmse"] - python["nrmse"]) < 1e-2, where
        assert np.abs(np.asarray(page_result["gate"]) - np.asarray(python["gate"])).max() < 1e-4, where
    assert sum(v["error"] is None for v in vectors["plays"]) > 20 and sum(v["error"] is not None
                                                                          for v in vectors["plays"]) > 10
    assert not errors
