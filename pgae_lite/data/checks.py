"""Checks on the authors' text files: bad values named by file and line (paper Sec. 4).

The authors' files (:mod:`pgae_lite.data.original`) are read row by row, so a row
that is short, long, not a number, not finite or far outside the data's range
stops loading with the file and the line that hold it, instead of shifting
the rows after it or training on NaN. (A dataset from any source is checked
for non-finite values when a normaliser is fitted on it:
:meth:`pgae_lite.data.dataset.PGAEDataset.check_finite`.)

Bounds (measured on the authors' 864 samples): joints lie in [0, 1] (their
README: "already scaled to [0, 1] per joint"), visual features in
[-64.2, 76.2]. Values beyond :data:`JOINT_BOUNDS` (a whole range past either
end) or :data:`VISION_LIMIT` (over 10x the largest feature) are not data but
damage: one joint at 1e30 would make every nRMSE print 0.000%.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from pgae_lite.data.dataset import DataFormatError
from pgae_lite.world.words import SIGNALS, VOCABULARY

#: Joint values allowed in the authors' files: their [0, 1] with a range's margin.
JOINT_BOUNDS = (-1.0, 2.0)
#: Largest visual feature allowed (in absolute value) in the authors' files.
VISION_LIMIT = 1000.0


def text_of(path: Path) -> str:
    """The text of ``path``; :class:`~pgae_lite.data.dataset.DataFormatError` naming it if it is not text."""
    try:
        return path.read_text(encoding="utf-8")
    except UnicodeDecodeError as e:
        raise DataFormatError(f"{path} is not a text file (byte {e.start} is not UTF-8): the authors' files "
                              "are plain text, numbers and words") from None


def read_rows(path: Path, width: int) -> np.ndarray:
    """The numbers of a text file, ``width`` per row, as float32 (rows, width).

    Blank lines are skipped; every other line must hold exactly ``width``
    finite numbers, else :class:`~pgae_lite.data.dataset.DataFormatError` names the file and the line.
    """
    if not path.is_file():
        raise DataFormatError(f"missing file {path}: every sample needs the same file "
                              "name in all sub-folders")
    lines, fields = [], []
    for number, line in enumerate(text_of(path).splitlines(), 1):
        row = line.split()
        if not row:
            continue
        if len(row) != width:
            raise DataFormatError(f"{path}, line {number}: expected rows of {width} "
                                  f"numbers, found {len(row)}")
        lines.append(number)
        fields.append(row)
    if not lines:
        raise DataFormatError(f"{path}: expected rows of {width} numbers, found an "
                              "empty file")
    try:
        with np.errstate(over="ignore"):          # 1e39 -> inf, refused below
            values = np.array(fields, dtype=np.float32)               # (rows, width)
    except ValueError:
        number = next(n for n, row in zip(lines, fields) if not _numbers(row))
        raise DataFormatError(f"{path}, line {number}: expected rows of {width} "
                              "numbers, found text that is not a number") from None
    bad = ~np.isfinite(values)
    if bad.any():
        number, column = _first(bad, lines)
        raise DataFormatError(f"{path}, line {number}, column {column}: found "
                              f"{values[bad][0]}, but every value must be a finite "
                              "number")
    return values


def _numbers(row: list[str]) -> bool:
    try:
        [float(x) for x in row]
    except ValueError:
        return False
    return True


def _first(bad: np.ndarray, lines: list[int]) -> tuple[int, int]:
    """(line number, column from 1) of the first True of ``bad`` (rows, width)."""
    r, c = np.argwhere(bad)[0]
    return lines[r], int(c) + 1


def _lines(path: Path) -> list[int]:
    """Numbers of the non-blank lines of ``path`` (read again only on an error)."""
    lines = text_of(path).splitlines()
    return [n for n, line in enumerate(lines, 1) if line.strip()]


def check_range(path: Path, values: np.ndarray, lo: float, hi: float,
                what: str) -> None:
    """:class:`~pgae_lite.data.dataset.DataFormatError` naming the line if a value lies outside [lo, hi]."""
    bad = (values < lo) | (values > hi)
    if bad.any():
        number, column = _first(bad, _lines(path))
        raise DataFormatError(f"{path}, line {number}, column {column}: {what} "
                              f"{values[bad][0]:g} lies outside [{lo:g}, {hi:g}], far "
                              "beyond the authors' data (pgae_lite.data.checks)")


def check_one_hot(path: Path, rows: np.ndarray) -> None:
    """Every row of a language file must hold one 1 and zeros elsewhere."""
    ok = ((rows == 0) | (rows == 1)).all(1) & (rows.sum(1) == 1)
    if not ok.all():
        number = _lines(path)[int(np.argmin(ok))]
        raise DataFormatError(f"{path}, line {number}: a language row must be one-hot "
                              f"(a single 1, the other {rows.shape[1] - 1} numbers 0)")


def check_vocabulary(root: Path) -> None:
    """``vocabulary.txt`` must list the words, then the signals, in our order."""
    path = root / "vocabulary.txt"
    if not path.is_file():
        raise DataFormatError(f"missing {path} (the words and signals in index order, "
                              "from the authors' repository)")
    found = [line.strip() for line in text_of(path).splitlines() if line.strip()]
    expected = [*VOCABULARY, *(f"{s}:" for s in SIGNALS)]
    if found != expected:
        i = next((i for i, (a, b) in enumerate(zip(found, expected)) if a != b),
                 min(len(found), len(expected)))
        got = repr(found[i]) if i < len(found) else "the end of the file"
        want = repr(expected[i]) if i < len(expected) else "the end of the file"
        raise DataFormatError(f"{path}, word {i + 1}: found {got}, expected {want}; it "
                              f"must list the {len(VOCABULARY)} words and "
                              f"{len(SIGNALS)} signals in pgae_lite.world.words's order")


__all__ = ["JOINT_BOUNDS", "VISION_LIMIT", "read_rows", "text_of", "check_range", "check_one_hot",
           "check_vocabulary"]
