"""pgae_lite.world.words: vocabulary, synonyms, parsing, encoding, word weights."""
from __future__ import annotations

import re
from collections import Counter

import pytest
import torch

from pgae_lite.world import words as L
from pgae_lite.world.words import (
    BOS_EOS,
    INPUT_DIM,
    SIGNALS,
    VOCABULARY,
    LanguageError,
    decode,
    encode,
    equivalent_descriptions,
    is_correct,
    normalise_signal,
    one_hot,
    parse_description,
    signal_index,
    tokenize,
    word_weights,
)

AUTHORS_VOCABULARY = (
    "<BOS/EOS>", "azure", "blonde", "blue", "cyan", "fast", "green", "greenish-blue", "harlequin",
    "move-down", "move-sideways", "move-up", "pull", "purple", "push", "quickly", "red", "scarlet",
    "slide", "slowly", "unhurriedly", "violet", "yellow")


def test_vocabulary_is_the_authors():
    assert VOCABULARY == AUTHORS_VOCABULARY
    assert len(VOCABULARY) == 23
    assert VOCABULARY[0] == BOS_EOS
    assert L.WORD_INDEX == {w: i for i, w in enumerate(VOCABULARY)}


def test_vocabulary_matches_authors_file(original_data):
    lines = [x.strip() for x in (original_data / "vocabulary.txt").read_text().splitlines() if x.strip()]
    assert tuple(lines[:23]) == VOCABULARY
    assert tuple(s.rstrip(":") for s in lines[23:]) == SIGNALS


def test_input_dim_and_signals():
    assert INPUT_DIM == 28 == len(VOCABULARY) + len(SIGNALS)
    assert SIGNALS == ("describe", "execute", "repeat action", "repeat both", "repeat language")
    assert set(L.TEST_SIGNALS) == set(SIGNALS) - {"repeat both"}
    assert [signal_index(s) for s in SIGNALS] == [0, 1, 2, 3, 4]


def test_synonyms_cover_the_vocabulary():
    words = set(L.SYNONYMS) | set(L.SYNONYMS.values())
    assert len(words) == 22 and words | {BOS_EOS} == set(VOCABULARY)
    assert set(L.ACTIONS) | set(L.COLOURS) | set(L.SPEEDS) == set(L.SYNONYMS)


def test_eight_equivalent_descriptions_in_authors_order():
    alts = equivalent_descriptions("push", "red", "slowly")
    assert alts == [
        ("push", "red", "slowly"), ("move-up", "red", "slowly"),
        ("push", "scarlet", "slowly"), ("move-up", "scarlet", "slowly"),
        ("push", "red", "unhurriedly"), ("move-up", "red", "unhurriedly"),
        ("push", "scarlet", "unhurriedly"), ("move-up", "scarlet", "unhurriedly")]
    # Synonyms in, the same 8 (canonical first) out.
    assert equivalent_descriptions("move-sideways", "greenish-blue", "quickly") == \
        equivalent_descriptions("slide", "cyan", "fast")
    assert len(set(equivalent_descriptions("pull", "violet", "fast"))) == 8


@pytest.mark.parametrize("text, expected", [
    ("  PUSH   Red  FAST ", ("push", "red", "fast")),
    ("move up green slowly", ("push", "green", "slowly")),
    ("Move-Down greenish blue quickly", ("pull", "cyan", "fast")),
    ("move sideways purple unhurriedly", ("slide", "violet", "slowly")),
    ("<BOS/EOS> pull azure fast <BOS/EOS>", ("pull", "blue", "fast")),
])
def test_parse_is_lenient(text, expected):
    assert parse_description(text) == expected


def test_tokenize_joins_two_word_synonyms():
    assert tokenize("greenish blue") == ["greenish-blue"]
    assert tokenize("move up MOVE   down move-sideways") == ["move-up", "move-down", "move-sideways"]
    assert tokenize("") == []


def test_unknown_word_names_it_and_lists_the_vocabulary():
    with pytest.raises(LanguageError) as e:
        parse_description("push magenta fast")
    msg = str(e.value)
    assert "'magenta'" in msg
    for w in VOCABULARY[1:]:
        assert w in msg
    assert isinstance(e.value, ValueError)


def test_wrong_word_count():
    for text in ("push red", "push red fast slowly", ""):
        with pytest.raises(LanguageError, match="3 words"):
            parse_description(text)


@pytest.mark.parametrize("text, slot, allowed", [
    ("red push fast", "action", ["push", "move-up", "pull", "move-down", "slide", "move-sideways"]),
    ("push fast red", "colour", ["red", "scarlet", "greenish-blue", "purple"]),
    ("push red blue", "speed", ["slowly", "unhurriedly", "fast", "quickly"]),
])
def test_word_in_wrong_slot_says_what_is_allowed(text, slot, allowed):
    with pytest.raises(LanguageError) as e:
        parse_description(text)
    msg = str(e.value)
    assert slot in msg and "allowed" in msg
    for w in allowed:
        assert w in msg


def test_signals_normalise_and_errors():
    assert normalise_signal("repeat_action") == "repeat action"
    assert normalise_signal("Repeat Language:") == "repeat language"
    assert normalise_signal("  DESCRIBE ") == "describe"
    assert normalise_signal("repeat-both") == "repeat both"
    with pytest.raises(LanguageError) as e:
        normalise_signal("translate")
    msg = str(e.value)
    assert "'translate'" in msg
    for s in SIGNALS:
        assert s in msg
    with pytest.raises(LanguageError):
        signal_index("dance")


def test_encode_decode_round_trip():
    for alt in equivalent_descriptions("slide", "yellow", "fast"):
        idx = encode(alt)
        assert idx.tolist()[0] == 0 and idx.tolist()[-1] == 0 and len(idx) == 5
        assert decode(idx[1:]) == " ".join(alt)
        assert decode(one_hot(idx[1:])) == " ".join(alt)          # (steps, 23) rows
        assert decode(idx[1:].tolist()) == " ".join(alt)


def test_decode_stops_at_eos():
    assert decode(torch.tensor([0, 14, 16, 19])) == ""
    assert decode(torch.tensor([0])) == ""
    assert decode([14, 16, 0, 5]) == "push red"
    assert decode(one_hot(torch.tensor([0, 0, 0, 0]))) == ""


def test_one_hot_shapes():
    assert one_hot(torch.tensor([1, 2])).shape == (2, 23)
    assert one_hot(torch.tensor([[27]]), INPUT_DIM).shape == (1, 1, 28)


def test_is_correct():
    alts = equivalent_descriptions("push", "red", "slowly")
    assert is_correct("push red slowly", alts)
    assert is_correct("move-up scarlet unhurriedly", alts)
    assert not is_correct("push red fast", alts)
    assert not is_correct("push red", alts)
    assert not is_correct("", alts)
    assert is_correct("", None)
    assert not is_correct("push red slowly", None)


def test_word_weights_values():
    w = word_weights()
    assert w.shape == (23,)
    assert w[0] == pytest.approx(0.1168)
    for c in L.COLOURS:
        assert L.WORD_WEIGHTS[c] == L.WORD_WEIGHTS[L.SYNONYMS[c]] == pytest.approx(1.4010)
    for a in L.ACTIONS:
        assert L.WORD_WEIGHTS[a] == L.WORD_WEIGHTS[L.SYNONYMS[a]] == pytest.approx(0.7005)
    for s in L.SPEEDS:
        assert L.WORD_WEIGHTS[s] == L.WORD_WEIGHTS[L.SYNONYMS[s]] == pytest.approx(0.4670)
    assert [float(x) for x in w] == pytest.approx([L.WORD_WEIGHTS[v] for v in VOCABULARY])


def test_word_weights_are_inverse_frequency_with_mean_one():
    """Over all descriptions (decoder targets w1 w2 w3 <EOS>), weight x frequency is one constant,
    and the weights average to 1 over the 23 words."""
    counts = Counter()
    for a in L.ACTIONS:
        for c in L.COLOURS:
            for s in L.SPEEDS:
                for alt in equivalent_descriptions(a, c, s):
                    counts.update([*alt, BOS_EOS])
    total = sum(counts.values())
    products = [L.WORD_WEIGHTS[v] * counts[v] / total for v in VOCABULARY]
    assert max(products) / min(products) == pytest.approx(1.0, abs=1e-3)
    assert float(word_weights().mean()) == pytest.approx(1.0, abs=1e-3)


def test_wrong_count_message_gives_the_count():
    with pytest.raises(LanguageError) as e:
        parse_description("push red")
    assert re.search(r"got 2", str(e.value))
