"""The 144 patterns and their numbering: 12 cube arrangements x 12 actions, and the split.

Paper, Sec. 4 (Dataset). A pattern is one action (push, pull or slide the
left or the right cube, slowly or fast) in one arrangement of two coloured
cubes; the dataset records each pattern 6 times. Patterns are numbered as in
the authors' data::

    pattern = 72·speed + 6·arrangement + action

with speed 0 (slowly) or 1 (fast), arrangement 0-11 (:data:`ARRANGEMENTS`)
and action 0-5 (:data:`ACTION_SIDES`). :func:`pattern_number` is that sum,
:func:`pattern_parts` its inverse, and :class:`Pattern` names the words of a
number. 36 of the patterns are the test split (:data:`TEST_PATTERNS`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pgae_lite.world.words import WORD_INDEX, equivalent_descriptions

#: Steps of a slow recording, the longest: every sample is padded to it (a fast one lasts half).
MAX_STEPS = 100
#: The numbering of the patterns, in words (error messages quote it).
NUMBERING = "72 * speed + 6 * arrangement + action"
#: The 12 cube arrangements (left+right), in the order of the authors' data.
ARRANGEMENTS: tuple[tuple[str, str], ...] = (
    ("red", "blue"), ("green", "red"), ("blue", "green"), ("blue", "red"), ("red", "green"),
    ("green", "blue"), ("yellow", "violet"), ("cyan", "yellow"), ("violet", "cyan"),
    ("violet", "yellow"), ("yellow", "cyan"), ("cyan", "violet"))
#: Action order within an arrangement: (action, cube side).
ACTION_SIDES: tuple[tuple[str, str], ...] = (
    ("push", "L"), ("pull", "L"), ("slide", "L"), ("push", "R"), ("pull", "R"), ("slide", "R"))
#: The 36 test patterns of the paper's split (the authors' actions.txt): every word
#: and action type appears in test, but not these combinations of description,
#: action and arrangement.
TEST_PATTERNS: frozenset[int] = frozenset((
    2, 6, 9, 14, 17, 25, 31, 33, 34, 38, 42, 45, 50, 53, 61, 67, 69, 70, 74, 76, 77, 78, 79, 80,
    81, 84, 94, 110, 112, 113, 114, 115, 116, 117, 120, 130))


def pattern_number(speed: int, arrangement: int, action: int) -> int:
    """The pattern of ``action`` (0-5) in ``arrangement`` (0-11) at ``speed`` (0 slowly, 1 fast).

    pattern = 72·speed + 6·arrangement + action; element-wise on numpy arrays too.
    """
    return 72 * speed + 6 * arrangement + action


def pattern_parts(number: int) -> tuple[int, int, int]:
    """(speed, arrangement, action) of a pattern number: the inverse of :func:`pattern_number`.

    Element-wise on numpy arrays too; the range (0-143) is not checked here.
    """
    return number // 72, number % 72 // 6, number % 6


@dataclass(frozen=True)
class Pattern:
    """One of the 144 patterns: pattern = 72·speed + 6·arrangement + action."""

    number: int
    action: str        # push | pull | slide
    side: str          # L | R: which cube, from NICO's point of view
    speed: str         # slowly | fast
    left: str          # colour of the left cube
    right: str         # colour of the right cube

    @classmethod
    def from_number(cls, number: int) -> "Pattern":
        if not 0 <= number < 144:
            raise ValueError(f"pattern number {number} out of range; patterns are 0-143")
        speed, arrangement, action = pattern_parts(number)
        act, side = ACTION_SIDES[action]
        left, right = ARRANGEMENTS[arrangement]
        return cls(number, act, side, ("slowly", "fast")[speed], left, right)

    @property
    def colour(self) -> str:
        """Colour of the manipulated cube."""
        return self.left if self.side == "L" else self.right

    @property
    def is_test(self) -> bool:
        return self.number in TEST_PATTERNS

    @property
    def steps(self) -> int:
        """Length of a recording: 100 steps slowly, 50 fast."""
        return MAX_STEPS if self.speed == "slowly" else MAX_STEPS // 2

    @property
    def code(self) -> str:
        """The authors' label, e.g. ``PUSH-L-SLOW``."""
        return f"{self.action.upper()}-{self.side}-{'SLOW' if self.speed == 'slowly' else 'FAST'}"

    def descriptions(self) -> np.ndarray:
        """Word indices of the 8 equivalent descriptions, (8, 3)."""
        alts = equivalent_descriptions(self.action, self.colour, self.speed)
        return np.array([[WORD_INDEX[w] for w in alt] for alt in alts])


__all__ = ["Pattern", "pattern_number", "pattern_parts", "ARRANGEMENTS", "ACTION_SIDES", "TEST_PATTERNS",
           "MAX_STEPS", "NUMBERING"]
