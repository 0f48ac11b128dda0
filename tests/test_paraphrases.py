"""The held-out paraphrases: fixed, complete for the test instructions, unreadable by the LSTM's vocabulary."""
from __future__ import annotations

import pytest

from pgae_lite.freeform.paraphrases import load_paraphrases, paraphrases_for
from pgae_lite.world.patterns import TEST_PATTERNS, Pattern
from pgae_lite.world.words import LanguageError, parse_description, tokenize


def test_three_paraphrases_for_every_test_instruction():
    paraphrases = load_paraphrases()
    test_meanings = {(p.action, p.colour, p.speed) for p in map(Pattern.from_number, TEST_PATTERNS)}
    assert {p.meaning for p in paraphrases} == test_meanings
    for meaning in test_meanings:
        assert len(paraphrases_for(*meaning)) == 3
    assert len({p.text.lower() for p in paraphrases}) == len(paraphrases) == 108


def test_the_fixed_vocabulary_rejects_every_paraphrase_naming_the_unknown_words():
    for p in load_paraphrases():
        with pytest.raises(LanguageError) as e:
            parse_description(p.text)
        message = str(e.value)
        assert "unknown word" in message and "the vocabulary is" in message
        unknown = [w for w in p.text.lower().replace(",", " ").split()
                   if w not in {"push", "pull", "slide", "red", "green", "blue", "yellow", "cyan", "violet",
                                "purple", "scarlet", "harlequin", "azure", "blonde", "slowly", "fast", "quickly"}]
        assert repr(unknown[0]) in message


def test_tokenize_names_all_unknown_words_once():
    with pytest.raises(LanguageError) as e:
        tokenize("please push the red block, the red one")
    msg = str(e.value)
    assert "'please'" in msg and "'block'" in msg and "'one'" in msg and msg.count("'the'") == 1


def test_a_malformed_file_is_refused(tmp_path):
    bad = tmp_path / "p.tsv"
    bad.write_text("action\tcolour\tspeed\ttext\nshove\tred\tslowly\tshove it\n")
    with pytest.raises(ValueError, match="shove"):
        load_paraphrases(bad)
