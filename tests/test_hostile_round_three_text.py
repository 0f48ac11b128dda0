"""Hostile input, round three (issue 62): the robot reads text as a person types it.

One test per kind of input: Unicode marks, spaces and fullwidth letters read once, the same way in
Python and in the page (node runs the page's own scripts on vectors Python writes); a verb the world
lacks behind the word lookup; polite negations acted on, genuine ones refused; repetitions, quantifiers,
opposite ways and a negated speed refused with a reason; a said-back colour absent from the table; very
long text and nested brackets; and the smaller items, each a clear error.
"""
from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import pytest
import torch

from pgae_lite.freeform.phrase_lexicon import training_lexicon
from pgae_lite.freeform.phrasings import slot_meanings
from pgae_lite.freeform.refusal_cases import SCENE, refusal_cases
from pgae_lite.freeform.refusals import CannotDo, check_instruction, refusal
from pgae_lite.freeform.word_lookup import WordLookup
from pgae_lite.robot.instructions import execute_paraphrases
from pgae_lite.util.errors import ArgumentError, PGAELiteError
from pgae_lite.world.typed import marks_table, normalise_typed
from pgae_lite.world.words import LanguageError, one_hot, parse_description, tokenize

ROOT = Path(__file__).resolve().parents[1]
NODE = shutil.which("node")


class Plain:
    """An encoder without a word lookup: the words are read through the training lexicon."""

    word_lookup = None


class Looked:
    """An encoder whose word lookup reads words never trained on through WordNet (as the free-form variant's)."""

    word_lookup = WordLookup(training_lexicon())


class HeldOut:
    """The lookup of a training that held words out: they are looked up, and still words of the world."""

    word_lookup = WordLookup(training_lexicon("held-out"))


#: Typed as a phone, a word processor or a fullwidth keyboard writes it -> what every reader reads.
TYPED = {
    "don\u2019t push the red cube": "don't push the red cube",             # right single quotation mark
    "don\u2018t push": "don't push", "don\u02bct push": "don't push", "don\u2032t push": "don't push",
    "don`t push": "don't push", "don\u00b4t push": "don't push", "don\uff07t push": "don't push",
    "\u201cpush\u201d the cube": '"push" the cube', "\u00abpush\u00bb": '"push"',
    "push \u2013 now": "push - now", "push\u2014now": "push-now", "push \u2212 x": "push - x", "a\u2010b": "a-b",
    "pu\u200bsh": "push", "pu\u200csh": "push", "pu\u200dsh": "push", "pu\u2060sh": "push", "\ufeffpush": "push",
    "pu\u00adsh": "push",                                                      # soft hyphen
    "\uff50\uff55\uff53\uff48 \uff52\uff45\uff44 \uff46\uff41\uff53\uff54": "push red fast",  # fullwidth
    "push\u00a0red\u2003fast\u3000now": "push red fast now",                    # no-break, em and ideographic spaces
    "PUSH The Red Cube": "PUSH The Red Cube",                                   # case: each reader folds it
}


def test_typed_text_is_read_in_one_plain_form():
    for typed, plain in TYPED.items():
        assert normalise_typed(typed) == plain, typed
        assert normalise_typed(plain) == plain                                  # once is enough
    assert tokenize("\uff50\uff55\uff53\uff48 red\u00a0fast") == ["push", "red", "fast"]
    assert parse_description("PUSH\u200b red fast") == ("push", "red", "fast")
    assert HeldOut.word_lookup.rewrite("slide the amethyst\u00a0cube") == "slide the purple cube"
    with pytest.raises(PGAELiteError, match="must be a string"):
        normalise_typed(None)


def _node(script: str, data: dict, tmp_path: Path):
    """``script`` run by node with the page's pgae-logic.js and pgae-refusals.js loaded and ``data`` as DATA."""
    if NODE is None:
        pytest.skip("node is not installed")
    (tmp_path / "data.json").write_text(json.dumps(data), encoding="utf-8")
    body = f"""globalThis.window = {{}};
require({json.dumps(str(ROOT / "book/_js/pgae-logic.js"))});
require({json.dumps(str(ROOT / "book/_js/pgae-refusals.js"))});
const DATA = JSON.parse(require("fs").readFileSync({json.dumps(str(tmp_path / "data.json"))}, "utf8"));
{script}"""
    (tmp_path / "run.js").write_text(body, encoding="utf-8")
    done = subprocess.run([NODE, str(tmp_path / "run.js")], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def _manifest() -> dict:
    from pgae_lite.web.messages import page_messages
    from pgae_lite.world.typed import typed_rules
    from pgae_lite.world.words import DEFAULT_LEXICON, SLOT_NAMES, SLOTS, SYNONYMS, VOCABULARY

    return {"typed": typed_rules(), "messages": page_messages(), "vocabulary": list(VOCABULARY), "play": {},
            "joint_units": [0, 1], "vision_dim": 30, "joint_dim": 5, "synonyms": SYNONYMS,
            "canonical": dict(DEFAULT_LEXICON.canonical), "slots": [list(s) for s in SLOTS],
            "slot_names": list(SLOT_NAMES)}


def test_the_page_reads_typed_text_as_python_does(tmp_path):
    texts = list(TYPED) + ["".join(marks_table()) + " push", "caf\u00e9 \u00bd \u2460 \ufb01 \u2126 \u212b x\u0301"]
    got = _node("console.log(JSON.stringify(DATA.texts.map(t => window.pgaeLogic.make(DATA.manifest)"
                ".normaliseTyped(t))));", {"manifest": _manifest(), "texts": texts}, tmp_path)
    assert got == [normalise_typed(t) for t in texts]


HOSTILE_THREE = [  # (text, encoder's name, readback or None): judged by Python and by the page
    ("lift the red cube", "looked", None), ("throw the blue cube", "looked", None),
    ("could you hoist the red block", "looked", None), ("pick up the red cube", "looked", None),
    ("knock the red cube over", "looked", None), ("yank the red cube back", "looked", None),
    ("poke the red cube away", "looked", None), ("push the red cube fast", "looked", "push yellow fast"),
    ("ｌｉｆｔ the red cube", "looked", None), ("don\u2019t drag the red cube", "looked", None),
    ("can\u2019t you push the red cube?", "plain", None), ("do not hesitate to slide the blue cube", "plain", None),
    ("ok, forget about the blue one and pull the red one", "plain", None),
    ("push the red cube 3 times", "plain", None), ("push any of the cubes", "plain", None),
    ("push the red cube up or down", "plain", None), ("pull the red cube, not slowly", "plain", None),
]


def test_the_page_refuses_what_python_refuses(tmp_path):
    from pgae_lite.web.refusal_data import front_coded, model_reading, shared_words

    encoders = {"plain": Plain(), "looked": Looked()}
    cases = [dict(c, model="plain") for c in refusal_cases()]
    cases += [{"text": t, "scene": list(SCENE), "understood": u, "model": m} for t, m, u in HOSTILE_THREE]
    for case in cases:
        lookup = encoders[case["model"]].word_lookup
        text = normalise_typed(case["text"])
        case["read"] = lookup.rewrite(text) if lookup else text
        case["swapped"] = [list(p) for p in lookup.replacements(text).items()] if lookup else []
        case["says"] = refusal(case["text"], encoders[case["model"]], case["scene"] and tuple(case["scene"]),
                               case["understood"])
    words = {w for c in cases for w in tokenize_words(c["text"] + " " + c["read"])}
    shared = shared_words(words)
    table = {w: r for c in cases for w, r in c["swapped"]}
    data = {"manifest": _manifest(), "shared": shared | {"verbs": front_coded(shared["verbs"])}, "cases": cases,
            "models": {name: model_reading(e, shared, table if e.word_lookup else {}) for name, e in encoders.items()}}
    got = _node("""const L = window.pgaeLogic.make(DATA.manifest), make = window.pgaeRefusals.make(DATA.shared, L);
const rules = Object.fromEntries(Object.entries(DATA.models).map(([k, v]) => [k, make(v)]));
const back = (u) => {
  try { return {words: u, meaning: L.parseDescription(u)}; } catch (e) { return {words: u, meaning: null}; }
};
console.log(JSON.stringify(DATA.cases.map(c => rules[c.model].refusal(L.normaliseTyped(c.text), c.read, c.swapped,
    c.scene, c.understood === null ? null : back(c.understood)))));""", data, tmp_path)
    wrong = [(c["text"], c["says"], g) for c, g in zip(cases, got) if g != c["says"]]
    assert not wrong, wrong[:5]
    assert sum(g is not None for g in got) > 40


def tokenize_words(text: str) -> list[str]:
    import re

    return re.findall(r"[a-z']+", text.lower())


def test_unicode_punctuation_does_not_hide_a_negation():
    for text in ("don\u2019t push the red cube", "don\u02bct push the red cube", "do\u200bn't push the red cube",
                 "\uff44\uff4f\uff4e\uff07\uff54 push the red cube", "don\u00b4t push the red cube"):
        assert "what not to do" in refusal(text, Plain(), SCENE), text
    assert refusal("\uff50\uff55\uff53\uff48 the red cube", Plain(), SCENE) is None


def test_a_verb_the_world_lacks_is_refused_whatever_the_lookup_reads_it_as():
    for verb in ("lift", "throw", "hoist", "squeeze", "kick", "carry", "raise", "flip"):
        said = refusal(f"{verb} the red cube", Looked(), SCENE)
        assert said is not None and "I can" in said, verb
    assert "I can't 'lift' a cube" in refusal("lift the red cube", Looked(), SCENE)
    assert "I can't 'pick' a cube" in refusal("pick up the red cube", Looked(), SCENE)        # up: no pull
    assert refusal("yank the red cube back", Looked(), SCENE) is None                        # its direction agrees
    assert refusal("prod the red cube", HeldOut(), SCENE) is None                            # a word of the world


def test_polite_negations_that_ask_for_one_action_are_acted_on():
    for text in ("can't you push the red cube?", "don't forget to push the red cube",
                 "never mind the blue one, push the red cube", "won't you pull the red cube",
                 "couldn't you slide the blue block?", "do not hesitate to push the red cube",
                 "forget the blue cube, pull the red one", "why don't you push the red cube",
                 "don\u2019t you ever forget to pull the blue cube"):
        assert refusal(text, Plain(), SCENE) is None, text
    for text in ("don't you push the red cube", "could you not push the red cube", "never push the red cube",
                 "forget pushing the blue cube", "please don't pull the blue one"):
        assert "what not to do" in refusal(text, Plain(), SCENE), text


@pytest.mark.parametrize("text, says", [
    ("push the red cube twice", "more than once ('twice')"),
    ("push the red cube three times", "more than once ('three times')"),
    ("pull the blue cube again and again", "more than once ('again and again')"),
    ("give the red cube two pushes", "more than once ('two pushes')"),
    ("push every cube", "more than one cube ('every')"),
    ("push both cubes", "more than one cube ('both')"),
    ("pull all the blocks", "more than one cube ('all')"),
    ("slide each cube", "more than one cube ('each')"),
    ("push the two cubes", "more than one cube ('cubes')"),
    ("push the red cube left and right", "two opposite ways ('left', 'right')"),
    ("move the red cube up and down", "two opposite ways ('up', 'down')"),
    ("push and pull the red cube", "2 actions (push, pull)"),
    ("push the red cube slowly and quickly", "2 speeds"),
])
def test_more_than_one_act_or_cube_is_refused_with_its_reason(text, says):
    said = refusal(text, Plain(), SCENE)
    assert said is not None and says in said and "tell me one action on one cube" in said


def test_a_negated_speed_is_not_done_at_that_speed():
    said = refusal("could you please not be slow and push the red cube", Plain(), SCENE)
    assert "what speed not to use ('not be slow')" in said and "'push the red cube fast'" in said
    assert refusal("push the red cube slowly, not fast", Plain(), SCENE) is None            # the speed is said


def test_a_said_back_colour_not_on_the_table_is_refused_named_or_not():
    assert "I understood 'push yellow fast'" in refusal("push the red cube fast", Plain(), SCENE, "push yellow fast")
    assert refusal("push the red cube fast", Plain(), SCENE, "push red fast") is None
    long = "push the red cube " + "and I really mean it " * 600                        # 12,000 characters
    with pytest.raises(CannotDo, match="is too long: I read at most 1000"):
        check_instruction(long, Plain(), SCENE, "push green fast")


def test_very_long_text_and_nested_brackets_are_a_clear_error_or_read():
    nested = "(" * 300 + "push the red cube" + ")" * 300
    assert refusal(nested, Plain(), SCENE) is None                                       # read, no traceback
    assert "is too long" in refusal("(" * 5000 + "push the red cube" + ")" * 5000, Plain(), SCENE)
    with pytest.raises(LanguageError, match="unknown word"):
        parse_description("((((push)))) red fast" + "x" * 100_000)


def test_the_smaller_items_are_each_a_clear_error():
    with pytest.raises(LanguageError, match=r"one_hot takes word indices, whole numbers 0-22"):
        one_hot(torch.tensor([3, 23]))
    with pytest.raises(LanguageError, match=r"one_hot takes word indices"):
        one_hot(torch.tensor([-1]))
    assert one_hot(torch.tensor([0, 22])).shape == (2, 23)
    from pgae_lite.bert.pretrained import tokens_to_text
    with pytest.raises(LanguageError, match=r"tokens_to_text reads token ids 0-27"):
        tokens_to_text([24, 99, 0])
    with pytest.raises(PGAELiteError, match="must be a string"):
        Looked.word_lookup.rewrite(None)
    with pytest.raises(PGAELiteError, match="must be"):
        refusal(None, Plain(), SCENE)
    with pytest.raises(LanguageError, match="must be a string"):
        slot_meanings(None)
    with pytest.raises(ArgumentError, match=r"scene must be the colours of the \(left, right\) cubes"):
        refusal("push the red cube", Plain(), "red blue")
    with pytest.raises(PGAELiteError, match="encoder must be a model's language encoder"):
        refusal("push the red cube", None, SCENE)
    with pytest.raises(ValueError, match="the closed loop needs the CAE"):
        execute_paraphrases(None, None, None, None, closed=True)


@pytest.fixture(scope="module")
def smoke_runs(smoke_episodes):
    """The smoke data and the pipeline's PGAE and PGAE-BERT (cached)."""
    from pgae_lite.config import get_profile
    from pgae_lite.runs.data import simulated_dataset
    from pgae_lite.runs.pipeline import trained_model
    from pgae_lite.runs.rows import TRAININGS

    smoke = get_profile("smoke")
    return simulated_dataset(smoke, "cpu", progress=False), {
        name: trained_model(TRAININGS[name], smoke, 0, device="cpu", progress=False) for name in ("PGAE", "PGAE-BERT")}


def test_play_reads_typed_text_once_before_the_rule_and_the_encoder(smoke_runs):
    pytest.importorskip("transformers")
    from pgae_lite.robot.playground import play
    from pgae_lite.world.patterns import ARRANGEMENTS

    data, runs = smoke_runs
    left = ARRANGEMENTS[0][0]
    lstm, bert = runs["PGAE"], runs["PGAE-BERT"]
    typed = play(lstm.model, None, lstm.normaliser, data, "execute", 0, 0,
                 f"\uff50\uff55\uff53\uff48\u00a0{left} fast", loop=None)          # fullwidth, a no-break space
    assert typed.told == f"execute push {left} fast"
    with pytest.raises(CannotDo, match="what not to do"):
        play(bert.model, None, bert.normaliser, data, "execute", 0, 0, f"don\u2019t push the {left} cube", loop=None)
    nested = "(" * 200 + f"push the {left} cube" + ")" * 200
    try:
        play(bert.model, None, bert.normaliser, data, "execute", 0, 0, nested, loop=None)
    except CannotDo as e:                                                           # a clear sentence, or read
        assert "I understood" in str(e) or "I can" in str(e)
