"""What a result file may hold before the README or the book renders it (not in the paper).

A result file (``results/*.json``, :mod:`pgae_lite.runs.results`) is data that a benchmark wrote
and a person may have edited, so every value is checked before it becomes text:

- text renders as itself in Markdown (:func:`text_of`): no table separator, tag, backquote, line
  break, control character, emphasis, link or entity;
- every number is finite and of a sane size (:data:`LARGEST`): the largest figure any benchmark
  writes is a byte count under 10^8, so a number past 10^12 (or a 309-digit one) is damage;
- every figure of a measure lies in that measure's range (:data:`MEASURES`, the one place that
  decides them): an accuracy or a share in % in [0, 100], an nRMSE in % in [0, 100].

Why an nRMSE stays at or below 100%: Table 1's nRMSE (paper Sec. 4, :mod:`pgae_lite.evaluate.table1`)
is the RMSE of the joints divided by the range the joints span over the whole dataset. The
action decoder writes through a tanh that the normaliser maps back into that range, and the
recorded joints lie in it too, so no error exceeds the range: 100% is a prediction at the far end
of the range at every step (the book's worst untrained model reads about 30%).

A figure's measure is read from its key path (:func:`measure_of`): the nearest key that names
one (``accuracy``; ``nrmse`` in any case; a ``%`` in the key: a share), or a Table 1 row's
``paper`` pair, [accuracy, nRMSE]. A figure that may pass 100 (a speed-up) is named without ``%``.
Every failure is a :class:`ResultFileError` naming the file, the key path and what is allowed.
"""
from __future__ import annotations

import math
import re

from pgae_lite.util.errors import PGAELiteError


class ResultFileError(PGAELiteError, ValueError):
    """A result file that is damaged, or holds what must not be rendered (one sentence naming the file)."""


# Text rendered into Markdown or HTML: no table cell separator, no tag, no backquote, no generated-block marker,
# no line break and no other control character (U+0085, U+2028 and U+2029 break lines too).
_MARKUP = re.compile(r"[|<>`\x00-\x1f\x7f-\x9f\u2028\u2029]")
# Outside a code span, also no emphasis, link, escape or entity.
_INLINE = re.compile(r"[|<>`\x00-\x1f\x7f-\x9f\u2028\u2029*_\[\]\\&]")

#: The largest size of any number in a result file: a thousand times past the largest figure a benchmark
#: writes (bytes of the playground's files, under 10^8); seconds, counts and percentages are far below it.
LARGEST = 1e12
#: Each measure: (name, how its keys read, low, high, what it is). nRMSE first: "nRMSE %" is an nRMSE.
MEASURES = (
    ("nrmse", re.compile(r"nrmse", re.IGNORECASE), 0.0, 100.0,
     "an nRMSE in %: the joints' error over their range, which no prediction within the range exceeds"),
    ("accuracy", re.compile(r"accuracy|%", re.IGNORECASE), 0.0, 100.0, "an accuracy or a share in %"),
)
_RANGES = {name: (low, high, what) for name, _, low, high, what in MEASURES}


def text_of(value, where: str, code: bool = False) -> str:
    """``value`` when it is a string that renders as itself in Markdown (``code``: in a code span);
    else a :class:`ResultFileError`."""
    if not isinstance(value, str):
        raise ResultFileError(f"{where} must be a string; got {type(value).__name__} {value!r:.60}")
    found = (_MARKUP if code else _INLINE).search(value)
    if found:
        raise ResultFileError(f"{where} holds markup ({found.group(0)!r}: "
                              "a table separator, tag, backquote, line break, control character, emphasis, link "
                              f"or entity), which would not render as itself; got {value!r:.80}")
    return value


def measure_of(keys: list) -> str | None:
    """The measure (a name of :data:`MEASURES`) of the figure at key path ``keys``, or None when none is named."""
    if len(keys) >= 3 and keys[-3] == "paper" and keys[-1] in (0, 1) and isinstance(keys[-2], str):
        return ("accuracy", "nrmse")[keys[-1]]           # a Table 1 row's paper pair: [accuracy, nRMSE]
    for key in reversed(keys):
        if isinstance(key, str):
            for name, pattern, *_ in MEASURES:
                if pattern.search(key):
                    return name
    return None


def number_of(value, where: str, measure: str | None = None) -> float:
    """``value`` when it is a finite number (not a bool) of a sane size (:data:`LARGEST`) and, for a ``measure``
    (a name of :data:`MEASURES`), in its range; else a :class:`ResultFileError`."""
    low, high, what = _RANGES[measure] if measure else (-LARGEST, LARGEST, f"a size of at most {LARGEST:.0e}")
    number = not isinstance(value, bool) and isinstance(value, (int, float))
    if number and isinstance(value, float) and not math.isfinite(value):
        number = False
    if not number or not low <= value <= high:
        allowed = f"in [{low:g}, {high:g}] ({what})" if measure else f"of {what}"
        raise ResultFileError(f"{where} must be a finite number {allowed}; got {value!r:.60}")
    return float(value)


def check_figures(node, where: str, keys: list | None = None) -> None:
    """Every number under ``node`` (a result file's JSON, found at ``where``) through :func:`number_of`,
    with the measure its key path names."""
    keys = keys or []
    if isinstance(node, dict):
        for key, child in node.items():
            check_figures(child, f"{where}[{key!r}]", [*keys, key])
    elif isinstance(node, list):
        for i, child in enumerate(node):
            check_figures(child, f"{where}[{i}]", [*keys, i])
    elif isinstance(node, (int, float)) and not isinstance(node, bool):
        number_of(node, where, measure_of(keys))


def count_of(value, where: str) -> str:
    """``value`` as text when it is a whole number >= 1 (cores, threads) or a plain string; else a ResultFileError."""
    if isinstance(value, str):
        return text_of(value, where)
    if not isinstance(value, int) or isinstance(value, bool) or value < 1:
        raise ResultFileError(f"{where} must be a whole number >= 1 or a plain text; got {value!r:.60}")
    return str(value)


def seeds_of(value, where: str) -> list[int]:
    """``value`` when it is a non-empty list of whole numbers >= 0; else a :class:`ResultFileError`."""
    if not isinstance(value, list) or not value or \
            not all(isinstance(s, int) and not isinstance(s, bool) and s >= 0 for s in value):
        raise ResultFileError(f"{where} must be a list of whole numbers >= 0 (the seeds); got {value!r:.60}")
    return value


__all__ = ["LARGEST", "MEASURES", "ResultFileError", "check_figures", "count_of", "measure_of", "number_of",
           "seeds_of", "text_of"]
