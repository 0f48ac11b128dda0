"""The world's colours, words and patterns, and how to extend them with a new colour.

Not from the paper: the book's guided project "Teach NICO a new colour". The
paper's world (Sec. 4, Dataset) has six cube colours, 23 words, 12 cube
arrangements and 144 patterns; :data:`DEFAULT_WORLD` is exactly that world,
built from :mod:`pgae_lite.world.words` and :mod:`pgae_lite.world.patterns`, and
everything that takes a ``world`` (the simulator, the dataset cache, the
model) behaves bit for bit as before when given it or nothing.

:func:`with_colour` returns a larger world, never changing a module constant::

    world = with_colour("orange", synonym="amber", rgba=(0.98, 0.50, 0.05, 1.0))

- the word and its synonym are appended to the vocabulary (indices 23 and 24:
  the paper's words keep theirs, so the old data stays valid);
- each partner colour gives two new arrangements, (new, partner) and
  (partner, new), appended after the 12, and each arrangement 12 new
  patterns, numbered after the 144 (:data:`EXTENSION_NUMBERING`);
- a test split of the new patterns in the paper's spirit: every meaning of
  the new colour (action, speed) is held out in exactly one arrangement, on
  both cube sides, so every word and action type is seen in training and
  tested in a combination never trained (:func:`held_out`);
- the RGBA of the new cube goes to the simulator (:mod:`pgae_lite.sim.scene`); one the camera
  could not tell from a cube or the table is refused (:func:`nearest_seen`, the exercise's rule too).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import Sequence

import numpy as np

from pgae_lite.util.storage import config_digest
from pgae_lite.world.patterns import (
    ACTION_SIDES,
    ARRANGEMENTS,
    NUMBERING,
    TEST_PATTERNS,
    Pattern,
    pattern_number,
    pattern_parts,
)
from pgae_lite.world.words import COLOURS, DEFAULT_LEXICON, LanguageError, Lexicon, equivalent_descriptions

#: The paper's patterns: 0-143 (:data:`pgae_lite.world.patterns.NUMBERING`).
PAPER_PATTERNS = 144
#: How the patterns of an added arrangement (index 12 and up) are numbered.
EXTENSION_NUMBERING = "144 + 12 * (arrangement - 12) + 6 * speed + action"
#: The partner colours of a new colour unless told: one from each group of the paper.
DEFAULT_PARTNERS = ("blue", "violet")

RGBA = tuple[float, float, float, float]


@dataclass(frozen=True)
class WorldPattern(Pattern):
    """A :class:`~pgae_lite.world.patterns.Pattern` whose split and words are a world's."""

    world: World | None = field(default=None, compare=False, repr=False)

    @property
    def is_test(self) -> bool:
        return self.number in self.world.test_patterns

    def descriptions(self) -> np.ndarray:
        """Word indices of the 8 equivalent descriptions (the world's), (8, 3)."""
        lex = self.world.lexicon
        alts = equivalent_descriptions(self.action, self.colour, self.speed, lex)
        return np.array([[lex.word_index[w] for w in alt] for alt in alts])


#: RGBA of each cube colour, keyed by the colour words of :mod:`pgae_lite.world.words`.
CUBE_RGBA: dict[str, tuple[float, float, float, float]] = {
    "red": (0.86, 0.08, 0.06, 1.0),
    "green": (0.10, 0.72, 0.12, 1.0),
    "blue": (0.08, 0.22, 0.92, 1.0),
    "yellow": (0.96, 0.84, 0.06, 1.0),
    "cyan": (0.05, 0.82, 0.86, 1.0),
    "violet": (0.56, 0.16, 0.84, 1.0),
}
assert set(CUBE_RGBA) == set(COLOURS), "one RGBA per colour word of the language"
#: RGBA of the table the cubes stand on (light wood).
TABLE_RGBA = (0.80, 0.74, 0.64, 1.0)
#: Least difference, in the most different of R, G and B, between two colours the camera must tell apart.
MIN_COLOUR_DIFFERENCE = 0.2


def nearest_colour(rgba: Sequence[float], others: dict[str, Sequence[float]]) -> tuple[str, float]:
    """(the name of the colour of ``others`` nearest to ``rgba``, how far apart they are): the largest
    difference over R, G and B, as the CAE sees the three channels apart."""
    gaps = {name: max(abs(a - b) for a, b in zip(rgba[:3], other[:3])) for name, other in others.items()}
    closest = min(gaps, key=gaps.get)
    return closest, gaps[closest]


@dataclass(frozen=True)
class World:
    """Words, cube arrangements, test split, extra cube colours (default: the paper's).

    ``palette`` holds the RGBA of colours the simulator does not know
    (:data:`CUBE_RGBA` has the paper's six).
    """

    lexicon: Lexicon = DEFAULT_LEXICON
    arrangements: tuple[tuple[str, str], ...] = ARRANGEMENTS
    test_patterns: frozenset[int] = TEST_PATTERNS
    palette: tuple[tuple[str, RGBA], ...] = ()

    @property
    def n_patterns(self) -> int:
        """Number of patterns: 144, plus 12 per added arrangement."""
        return PAPER_PATTERNS + 12 * (len(self.arrangements) - len(ARRANGEMENTS))

    @property
    def new_patterns(self) -> tuple[int, ...]:
        """The patterns beyond the paper's 144."""
        return tuple(range(PAPER_PATTERNS, self.n_patterns))

    def pattern_number(self, speed: int, arrangement: int, action: int) -> int:
        """The paper's numbering to arrangement 11, then :data:`EXTENSION_NUMBERING`."""
        for name, value, count in (("speed", speed, 2), ("arrangement", arrangement, len(self.arrangements)),
                                   ("action", action, 6)):
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not 0 <= value < count:
                raise ValueError(f"{name} must be a whole number from 0 to {count - 1} in this world; got {value!r}")
        if arrangement < len(ARRANGEMENTS):
            return pattern_number(speed, arrangement, action)
        k = arrangement - len(ARRANGEMENTS)                # the k-th added arrangement
        return PAPER_PATTERNS + 12 * k + 6 * speed + action

    def pattern_parts(self, number: int) -> tuple[int, int, int]:
        """(speed, arrangement, action) of a pattern: the inverse of pattern_number."""
        last = self.n_patterns - 1
        if not isinstance(number, (int, np.integer)) or not 0 <= number <= last:
            extra = (f", and {PAPER_PATTERNS}-{last} as {EXTENSION_NUMBERING}"
                     if last >= PAPER_PATTERNS else "")
            raise ValueError(f"pattern number {number!r} out of range; patterns are "
                             f"0-143 ({NUMBERING}){extra}")
        if number < PAPER_PATTERNS:
            return pattern_parts(int(number))
        k, rest = divmod(int(number) - PAPER_PATTERNS, 12)
        return rest // 6, len(ARRANGEMENTS) + k, rest % 6

    def pattern(self, number: int) -> WorldPattern:
        """The pattern ``number`` (0 to :attr:`n_patterns` - 1) of this world."""
        speed, arrangement, action = self.pattern_parts(number)
        act, side = ACTION_SIDES[action]
        left, right = self.arrangements[arrangement]
        speed_word = ("slowly", "fast")[speed]
        return WorldPattern(int(number), act, side, speed_word, left, right, world=self)

    @cached_property
    def rgba(self) -> dict[str, RGBA]:
        """RGBA of the colours beyond the simulator's six."""
        return dict(self.palette)

    def to_dict(self) -> dict:
        """Plain values (it names the cache entries of this world's data and models)."""
        lex = self.lexicon
        return {"vocabulary": list(lex.vocabulary),
                "synonyms": [list(s) for s in lex.synonyms],
                "colours": list(lex.colours),
                "arrangements": [list(a) for a in self.arrangements],
                "test_patterns": sorted(self.test_patterns),
                "palette": [[c, list(v)] for c, v in self.palette]}

    def key(self) -> str:
        """Short digest of :meth:`to_dict`."""
        return config_digest(self.to_dict())


#: The paper's world: 23 words, 12 arrangements, 144 patterns, 36 of them test.
DEFAULT_WORLD = World()


def nearest_seen(rgba: Sequence[float], world: World | None = None, without: str | None = None) -> tuple[str, float]:
    """(what the camera sees nearest to ``rgba``, how far apart) among the cubes of ``world`` (the paper's six
    and any added colour, except ``without``) and the table: the rule :func:`with_colour` and the exercise's
    check_colour share. Below :data:`MIN_COLOUR_DIFFERENCE` apart the camera cannot tell the two apart."""
    cubes = {**CUBE_RGBA, **(world or DEFAULT_WORLD).rgba}
    seen = {**{f"the {c} cube": v for c, v in cubes.items() if c != without}, "the table": TABLE_RGBA}
    return nearest_colour(rgba, seen)


def held_out(j: int, action: int, speed: int, arrangements: int) -> bool:
    """Is ``action`` (0-5) at ``speed`` in the ``j``-th new arrangement a test pattern?

    With meaning m = (action mod 3) + 3 · speed (push, pull, slide; slowly, fast)
    and n new arrangements: test iff (m + j) mod n = 0. Every meaning is held out
    in exactly one arrangement, on both cube sides (so with the new colour's cube
    and with the partner's), and every action code once; with 2 partners (n = 4)
    12 of the 48 new patterns are test, the paper's quarter.
    """
    return ((action % 3) + 3 * speed + j) % arrangements == 0


def _check_rgba(name: str, rgba: Sequence[float]) -> RGBA:
    """``rgba`` as 4 floats when it is 4 numbers in [0, 1] with alpha 1.0; else a ValueError."""
    def in_range(v) -> bool:     # a number (not True or False, not text) from 0 to 1; NaN is not
        return isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(v, bool) and 0 <= v <= 1

    ok = (isinstance(rgba, (Sequence, np.ndarray)) and not isinstance(rgba, (str, bytes)) and len(rgba) == 4
          and all(in_range(v) for v in rgba) and rgba[3] == 1)
    if not ok:
        raise ValueError(f"rgba of {name!r} must be 4 numbers in [0, 1] with alpha 1.0 "
                         f"(an opaque cube), got {rgba!r:.80}; check it with "
                         "pgae_lite.exercises.check_colour")
    return tuple(float(v) for v in rgba)  # type: ignore[return-value]


def with_colour(name: str, synonym: str, rgba: Sequence[float],
                partners: Sequence[str] = DEFAULT_PARTNERS,
                world: World = DEFAULT_WORLD) -> World:
    """``world`` with one more cube colour: word and synonym, RGBA, new patterns.

    ``partners``: colours of ``world`` that the new cube shares the table with; each
    gives the arrangements (name, partner) and (partner, name), 24 new patterns.
    """
    if not isinstance(world, World):
        raise TypeError(f"world must be a World (DEFAULT_WORLD, or what with_colour returned); got {world!r:.60}")
    lexicon = world.lexicon.with_colour(name, synonym)   # LanguageError: a word taken
    values = _check_rgba(name, rgba)
    closest, gap = nearest_seen(values, world)
    if gap < MIN_COLOUR_DIFFERENCE:
        raise ValueError(f"rgba of {name!r} is too close to {closest} for the camera: no colour channel differs "
                         f"by more than {gap:.2f} (at least {MIN_COLOUR_DIFFERENCE} is needed); check it with "
                         "pgae_lite.exercises.check_colour")
    if not isinstance(partners, (list, tuple)):
        raise LanguageError(f"partners must be a list of colours of the world; got {partners!r:.60}")
    partners = tuple(partners)
    unknown = [p for p in partners if p not in world.lexicon.colours]
    if not partners or unknown or len(set(partners)) < len(partners):
        raise LanguageError("partners must be distinct colours of the world, at least "
                            f"one; got {partners}; the colours are: "
                            f"{', '.join(world.lexicon.colours)}")
    added = tuple(a for p in partners for a in ((name, p), (p, name)))
    start = len(world.arrangements)
    bigger = World(lexicon, world.arrangements + added, world.test_patterns,
                   world.palette + ((name, values),))
    test = {bigger.pattern_number(s, start + j, a) for j in range(len(added))
            for s in (0, 1) for a in range(6) if held_out(j, a, s, len(added))}
    return World(lexicon, bigger.arrangements, world.test_patterns | frozenset(test),
                 bigger.palette)


__all__ = ["World", "WorldPattern", "DEFAULT_WORLD", "with_colour", "held_out", "CUBE_RGBA", "TABLE_RGBA",
           "MIN_COLOUR_DIFFERENCE", "nearest_colour", "nearest_seen",
           "EXTENSION_NUMBERING", "DEFAULT_PARTNERS", "PAPER_PATTERNS"]
