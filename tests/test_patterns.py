"""pgae_lite.world.patterns: the 144 patterns, their numbering and the test split."""
from __future__ import annotations

import numpy as np
import pytest

from pgae_lite.data.dataset import description_text
from pgae_lite.world.patterns import ACTION_SIDES, ARRANGEMENTS, Pattern, pattern_number, pattern_parts
from pgae_lite.world.words import ACTIONS, COLOURS, SPEEDS, VOCABULARY, equivalent_descriptions

PATTERNS = [Pattern.from_number(i) for i in range(144)]


def test_144_patterns_12_arrangements_by_12_actions():
    arrangements = {(p.left, p.right) for p in PATTERNS}
    codes = {p.code for p in PATTERNS}
    assert len(arrangements) == 12 and len(codes) == 12
    assert len({((p.left, p.right), p.code) for p in PATTERNS}) == 144
    for p in PATTERNS:
        assert p.left != p.right
        group = {"red", "green", "blue"} if p.left in ("red", "green", "blue") else {"yellow", "cyan", "violet"}
        assert p.right in group                                  # both cubes from one colour group
        assert p.colour == (p.left if p.side == "L" else p.right)
        assert (p.speed == "slowly") == (p.number < 72)
    assert PATTERNS[0].code == "PUSH-L-SLOW" and (PATTERNS[0].left, PATTERNS[0].right) == ("red", "blue")
    assert PATTERNS[143].code == "SLIDE-R-FAST"


def test_pattern_number_out_of_range():
    for n in (-1, 144):
        with pytest.raises(ValueError, match="0-143"):
            Pattern.from_number(n)


def test_test_split_has_every_word_and_action_type():
    test = [p for p in PATTERNS if p.is_test]
    assert len(test) == 36
    assert {p.code for p in test} == {p.code for p in PATTERNS}          # all 12 action types
    words = {VOCABULARY[i] for p in test for alt in p.descriptions() for i in alt}
    assert words == set(VOCABULARY) - {"<BOS/EOS>"}                     # all 22 words
    assert {p.action for p in test} == set(ACTIONS)
    assert {p.colour for p in test} == set(COLOURS)
    assert {p.speed for p in test} == set(SPEEDS)


def test_pattern_descriptions():
    p = Pattern.from_number(2)                                           # SLIDE-L-SLOW, red+blue
    d = p.descriptions()
    assert d.shape == (8, 3)
    assert description_text(d[0]) == "slide red slowly"
    assert [tuple(description_text(r).split()) for r in d] == equivalent_descriptions("slide", "red", "slowly")


def test_patterns_match_authors_files(original_data):
    actions = [line.split() for line in (original_data / "actions.txt").read_text().splitlines() if line.strip()]
    arrangements = [line.strip() for line in (original_data / "arrangements.txt").read_text().splitlines()
                    if line.strip()]
    assert len(actions) == len(arrangements) == 144
    for p, (code, split), arr in zip(PATTERNS, actions, arrangements):
        assert p.code == code
        assert f"{p.left}+{p.right}" == arr
        assert p.is_test == (split == "test")


def test_pattern_number_and_its_inverse():
    numbers = [pattern_number(s, a, i) for s in (0, 1) for a in range(12) for i in range(6)]
    assert sorted(numbers) == list(range(144))
    for n in range(144):
        speed, arrangement, action = pattern_parts(n)
        assert pattern_number(speed, arrangement, action) == n
        p = Pattern.from_number(n)
        assert ("slowly", "fast")[speed] == p.speed and ARRANGEMENTS[arrangement] == (p.left, p.right)
        assert ACTION_SIDES[action] == (p.action, p.side)
    assert pattern_number(1, 7, 2) == 116 and pattern_parts(116) == (1, 7, 2)    # slide cyan (left) fast
    numbers = np.arange(144)                                             # element-wise on arrays too
    np.testing.assert_array_equal(pattern_number(*pattern_parts(numbers)), numbers)
