"""Checks of the world chapters' exercises: a longer vocabulary, a new cube colour.

Paper, Sec. 4 (the vocabulary of the descriptions) and our simulator's cube
colours (chapters 01, 02 and 03). Each check returns a
:class:`~pgae_lite.exercises.result.CheckResult`.
"""
from __future__ import annotations

import reprlib
from collections.abc import Sequence

from ..language import COLOURS, SIGNALS, VOCABULARY
from .result import CheckResult, _numbers


# ------------------------------------------------------------------ (f) vocabulary and colours
def check_vocabulary(words: Sequence[str], new: Sequence[str] = ()) -> CheckResult:
    """(f) An extended vocabulary: the 23 words in their order, then the new ones (``new``, if given)."""
    result = CheckResult("extended vocabulary")
    for name, given in (("words", words), ("new", new)):
        if (isinstance(given, (str, bytes)) or not isinstance(given, Sequence)
                or not all(isinstance(w, str) for w in given)):
            result.fail(f"{name} must be a list of strings; got {reprlib.repr(given)}",
                        "e.g. list(VOCABULARY) + ['orange', 'amber']")
            return result
    words = list(words)
    k = next((k for k, w in enumerate(VOCABULARY) if k >= len(words) or words[k] != w), None)
    if k is not None:
        result.fail(f"position {k} holds {words[k] if k < len(words) else 'nothing'!r}; expected {VOCABULARY[k]!r}",
                    "keep the 23 words in their order and append the new ones: a word's index is its one-hot "
                    "dimension and its row in every trained weight")
    else:
        result.ok(f"the {len(VOCABULARY)} words keep their order, <BOS/EOS> first")
    if len(set(words)) < len(words):
        result.fail(f"duplicate word(s) {sorted({w for w in words if words.count(w) > 1})}")
    added = [w for w in words if w not in VOCABULARY]
    for w in added:
        if not isinstance(w, str) or not w or w != w.strip().lower() or " " in w or w in SIGNALS:
            result.fail(f"{w!r} is not a lowercase word without spaces (nor a signal)",
                        "tokenize splits on spaces: join two words with a hyphen, as in greenish-blue")
    missing = [w for w in new if w not in added]
    if missing:
        result.fail(f"{missing} not among the new words {added}")
    if result:
        result.ok(f"new words {added}: {len(words)} output words, {len(words) + len(SIGNALS)} input dimensions")
    return result


def check_colour(name: str, rgba: Sequence[float], min_difference: float = 0.2) -> CheckResult:
    """(f) A new cube colour: one lowercase word and an opaque RGBA in [0, 1] that the camera can tell
    apart from the other cubes and the table (some channel differs by ``min_difference`` or more)."""
    from ..sim.scene import CUBE_RGBA, TABLE_RGBA  # here: pybullet loads only when needed

    result = CheckResult(f"cube colour {name!r}")
    if not isinstance(name, str) or not name or name != name.lower() or " " in name:
        result.fail(f"{name!r} should be one lowercase word (a hyphen joins two, as in greenish-blue)")
    elif name in COLOURS:
        result.fail(f"{name!r} is already one of the six colours of the dataset")
    values = _numbers(result, rgba, "the RGBA values")
    if values is None:
        return result.note("an RGBA colour is 4 numbers in [0, 1], alpha 1.0 last")
    if not all(0 <= v <= 1 for v in values):
        result.fail(f"the values must lie in [0, 1]; got {tuple(values)}",
                    "pybullet takes 0..1: divide 0..255 values by 255" if max(values) > 1 else None)
    if len(values) != 4:
        result.fail(f"an RGBA colour has 4 numbers; got {len(values)}", "add the alpha, 1.0" if len(values) == 3 else None)
    elif values[3] != 1.0:
        result.fail(f"alpha is {values[3]}; the cubes are opaque (alpha 1.0)")
    if not result:
        return result
    others = {**{f"the {c} cube": v for c, v in CUBE_RGBA.items() if c != name}, "the table": TABLE_RGBA}
    gaps = {o: max(abs(a - b) for a, b in zip(values, v[:3])) for o, v in others.items()}
    closest = min(gaps, key=gaps.get)
    if gaps[closest] < min_difference:
        result.fail(f"too close to {closest}: no colour channel differs by more than {gaps[closest]:.2f}",
                    f"the CAE sees R, G and B separately: make one channel differ by {min_difference} or more")
    else:
        result.ok(f"a valid opaque RGBA; the nearest is {closest}, {gaps[closest]:.2f} apart in the most different channel")
    return result


__all__ = ["check_vocabulary", "check_colour"]
