"""The phrasings generator: deterministic, on meaning, distinct, apart from the tests."""
from __future__ import annotations

import itertools
import random
import re
from dataclasses import replace

import pytest

from pgae_lite.freeform.paraphrases import load_paraphrases
from pgae_lite.freeform.phrase_lexicon import LEXICON, MEANINGS, SLOTS, held_out_words, words_of
from pgae_lite.freeform.phrasings import gerund, phrasing, phrasings, slot_meanings
from pgae_lite.util.errors import ArgumentError, ArgumentTypeError
from pgae_lite.world.words import SYNONYMS, VOCABULARY

ALL_MEANINGS = list(itertools.product(*(MEANINGS[slot] for slot in SLOTS)))


def test_same_seed_same_list_other_seed_other_list():
    first = phrasings("push", "red", "slowly", 25, seed=3)
    assert first == phrasings("push", "red", "slowly", 25, seed=3)
    assert first != phrasings("push", "red", "slowly", 25, seed=4)
    assert first[:10] == phrasings("push", "red", "slowly", 10, seed=3)


@pytest.mark.parametrize("action, colour, speed", ALL_MEANINGS)
def test_each_sentence_says_its_meaning_and_no_other(action, colour, speed):
    sentences = phrasings(action, colour, speed, 40, seed=1)
    assert len(set(sentences)) == 40
    for text in sentences:
        found = slot_meanings(text)
        assert set(found["action"]) == {action}, text
        assert found["colour"] == [colour], text
        assert found["speed"] == [speed], text


def test_no_phrase_says_two_meanings():
    meaning_of: dict[tuple[str, ...], tuple[str, str]] = {}
    for slot in SLOTS:
        for meaning, phrases in LEXICON.phrases(slot).items():
            assert phrases, (slot, meaning)
            for phrase in phrases:
                key = tuple(words_of(phrase))
                said = meaning_of.setdefault(key, (slot, meaning))
                assert said == (slot, meaning), key


def test_the_training_synonyms_are_words_of_the_lexicon():
    words = LEXICON.words()
    for word, synonym in SYNONYMS.items():
        assert set(words_of(word)) | set(words_of(synonym)) <= words, (word, synonym)


def test_frame_words_are_not_read_as_slot_phrases():
    found = slot_meanings("Go ahead and pull the crimson block toward you, nice and "
                          "slow")
    assert found == {"action": ["pull", "pull"], "colour": ["red"], "speed": ["slowly"]}
    found = slot_meanings("would you mind dragging the teal box fast?")
    assert found["action"] == ["pull"]


def test_held_out_words_never_appear():
    held = ("red", "crimson", "push", "slowly", "cube")
    lexicon = LEXICON.without(*held)
    assert "crimson" not in lexicon.words() and "navy" in lexicon.words()
    assert "bright red" not in lexicon.phrases("colour")["red"]
    for text in phrasings("push", "red", "slowly", 60, seed=2, lexicon=lexicon):
        assert not set(held) & set(words_of(text)), text
        found = slot_meanings(text)
        assert (set(found["action"]), found["colour"], found["speed"]) == (
            {"push"}, ["red"], ["slowly"]), text


def test_the_held_out_rule_keeps_every_meaning_sayable_and_the_dataset_words():
    held = held_out_words()
    assert held == held_out_words() and len(held) == len(set(held)) > 20
    assert not set(held) & {w for word in VOCABULARY for w in words_of(word)}
    lexicon = LEXICON.without(*held)
    assert not set(held) & lexicon.words()
    for meaning in ALL_MEANINGS:                               # every meaning can still be said
        for text in phrasings(*meaning, 5, lexicon=lexicon):
            assert not set(held) & set(words_of(text)), text


def test_generated_sentences_are_not_the_held_out_test_sentences():
    def norm(text: str) -> str:
        return " ".join(re.findall(r"[a-z']+", text.lower()))
    held_out = {norm(p.text) for p in load_paraphrases()}
    generated = {norm(t) for meaning in ALL_MEANINGS for seed in (0, 1, 2)
                 for t in phrasings(*meaning, 60, seed=seed)}
    shared = len(held_out & generated)   # a count only: the test sentences stay unread
    assert shared == 0


@pytest.mark.parametrize("args, words", [
    (("jump", "red", "fast"), ["action", "'jump'", "push, pull, slide"]),
    (("push", "pink", "fast"),
     ["colour", "'pink'", "red, green, blue, yellow, cyan, violet"]),
    (("push", "red", "medium"), ["speed", "'medium'", "slowly, fast"]),
])
def test_unknown_meaning_names_the_value_and_the_allowed(args, words):
    for call in (lambda: phrasings(*args, 3),
                 lambda: phrasing(*args, random.Random(0))):
        with pytest.raises(ArgumentError) as info:
            call()
        assert all(w in str(info.value) for w in words), str(info.value)


def test_bad_arguments_raise_clear_errors():
    with pytest.raises(ArgumentError, match="n must be a whole number >= 1; got 0"):
        phrasings("push", "red", "fast", 0)
    with pytest.raises(ArgumentTypeError, match="n must be"):
        phrasings("push", "red", "fast", 2.5)
    with pytest.raises(ArgumentTypeError, match="seed must be"):
        phrasings("push", "red", "fast", 2, seed="1")
    with pytest.raises(ArgumentTypeError, match="rng must be a random.Random"):
        phrasing("push", "red", "fast", 0)
    with pytest.raises(ArgumentTypeError, match="lexicon must be a PhraseLexicon"):
        phrasing("push", "red", "fast", random.Random(0), lexicon={"red": "red"})
    with pytest.raises(ArgumentTypeError, match="words must be strings"):
        LEXICON.without("red", 3)
    with pytest.raises(ArgumentError, match="slot 'size' is not one of: action"):
        LEXICON.phrases("size")


def test_too_few_words_or_sentences_is_said():
    cyan_words = {w for p in LEXICON.colours["cyan"] for w in words_of(p)}
    no_cyan = LEXICON.without(*cyan_words)
    with pytest.raises(ArgumentError, match="no word for the colour 'cyan'"):
        phrasings("pull", "cyan", "fast", 2, lexicon=no_cyan)
    mute = LEXICON.without(*LEXICON.verbs["slide"], *LEXICON.neutral)
    with pytest.raises(ArgumentError, match="no verb for the action 'slide'"):
        phrasings("slide", "red", "fast", 2, lexicon=mute)
    tiny = replace(LEXICON, verbs={"push": ("push",)}, steered={}, neutral=(),
                   directions={}, frames=(), gerund_frames=(), carriers=(),
                   nouns=("cube",),
                   sizes=(), determiners=("the",), colours={"red": ("red",)},
                   speeds={"fast": ("fast",)}, adjectives={})
    with pytest.raises(ArgumentError, match="400 is more than the [0-9]+ distinct"):
        phrasings("push", "red", "fast", 400, lexicon=tiny)


def test_gerunds():
    words = ("push", "slide", "drag", "tug", "budge", "draw", "propel")
    assert [gerund(w) for w in words] == ["pushing", "sliding", "dragging", "tugging",
                                          "budging", "drawing", "propelling"]
