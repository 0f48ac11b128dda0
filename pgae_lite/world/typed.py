"""Text as a person types it, read one way before anything reads it (not in the paper).

Paper, Sec. 3: PGAE-BERT "has the potential to recognise unseen natural language". A phone or a word
processor types "don’t" (U+2019), a non-breaking space, an en dash, a zero-width space between two
letters, or fullwidth letters; read as ``[a-z']+``, "don’t" is "don" and "t" and the negation is lost.
So, not in the paper, every typed text is first put in one plain form, by :func:`normalise_typed`,
before the word lookup, the refusal rule and the encoder read it::

    normalise_typed(t) = marks(NFKC(marks(t)))

    NFKC     Unicode's compatibility form: fullwidth "ｐｕｓｈ" -> "push", "ﬁ" -> "fi", U+00A0 -> " "
    marks    each character of :func:`marks_table` replaced, by its Unicode category and name:
             format characters (Cf: zero-width spaces and joiners U+200B-U+200D, U+2060, U+FEFF,
             the soft hyphen, direction marks)         -> removed
             spaces and separators (Zs, Zl, Zp)        -> " "
             dashes (Pd) and the minus sign            -> "-"
             single quotation marks, apostrophes, primes, the grave and acute accents -> "'"
             double quotation marks, double primes, guillemets                        -> '"'

(``marks`` runs before NFKC too, as NFKC writes the acute accent U+00B4 as a space and a combining
accent.) Case is left as typed: every reader of words folds it (``str.lower``), and the transformer's
tokenizer is uncased. The page applies the same two steps (``String.prototype.normalize("NFKC")`` and
this table, written into its data at build time: ``book/_js/pgae-logic.js``).
"""
from __future__ import annotations

import re
import sys
import unicodedata
from functools import lru_cache

from pgae_lite.util.errors import ArgumentTypeError

# Unicode names of the marks read as an apostrophe, and of those read as a double quotation mark.
_DOUBLE = re.compile(r"(DOUBLE|TRIPLE|QUADRUPLE).*(QUOTATION MARK|PRIME|APOSTROPHE)|DOUBLE ANGLE QUOTATION")
_SINGLE = re.compile(r"APOSTROPHE|QUOTATION MARK|PRIME|^(GRAVE|ACUTE) ACCENT$"
                     r"|^MODIFIER LETTER (TURNED|REVERSED) COMMA$")
# The categories a quotation mark may have (Lm: ʼ, a modifier letter; So: the ornaments ❛ ❜).
_MARK_CATEGORIES = ("Pi", "Pf", "Ps", "Pe", "Po", "Sk", "Lm", "So")
# Dashes that Unicode does not class as dash punctuation (Pd).
_OTHER_DASHES = ("\u2212", "\u2043", "\ufe63")


def _replacement(char: str) -> str | None:
    """What ``char`` is read as (a plain mark, a space, nothing), or None: it stays."""
    category, name = unicodedata.category(char), unicodedata.name(char, "")
    if char in " -'\"":                                       # the plain forms themselves
        return None
    if category == "Cf":
        return ""
    if category in ("Zs", "Zl", "Zp"):
        return " "
    if category == "Pd" or char in _OTHER_DASHES:
        return "-"
    if category in _MARK_CATEGORIES and not name.startswith(("NKO ", "ARMENIAN ")):
        if _DOUBLE.search(name):
            return '"'
        if _SINGLE.search(name):
            return "'"
    return None


@lru_cache(maxsize=1)
def marks_table() -> dict[str, str]:
    """Every character :func:`normalise_typed` replaces -> what it is read as (a few hundred, by their
    Unicode category and name; the page reads this table)."""
    table = {}
    for code in range(sys.maxunicode + 1):
        char = chr(code)
        if 0xD800 <= code <= 0xDFFF:                          # surrogates: not characters
            continue
        read = _replacement(char)
        if read is not None:
            table[char] = read
    return table


@lru_cache(maxsize=1)
def _translation() -> dict[int, str]:
    return {ord(char): read for char, read in marks_table().items()}


def normalise_typed(text: str) -> str:
    """``text`` in the one plain form every reader reads (see the module docstring):
    ``normalise_typed("don’t ｐｕｓｈ\\u200b it")`` -> ``"don't push it"``. Idempotent."""
    if not isinstance(text, str):
        raise ArgumentTypeError(f"the text must be a string, e.g. 'push the red cube'; got {type(text).__name__} "
                                f"{text!r:.60}")
    table = _translation()
    return unicodedata.normalize("NFKC", text.translate(table)).translate(table)


def typed_rules() -> dict:
    """What the page needs to apply :func:`normalise_typed`: the table, and the Unicode version of the
    NFKC form Python applies."""
    return {"marks": marks_table(), "unicode": unicodedata.unidata_version}


__all__ = ["marks_table", "normalise_typed", "typed_rules"]
