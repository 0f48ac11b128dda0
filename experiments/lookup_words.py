"""Lookup words: does the WordNet lookup read a word it never trained on as its own meaning?

    python experiments/lookup_words.py

No PGAE, no transformer, no training: :class:`pgae_lite.freeform.word_lookup.WordLookup`
alone, on the one-word phrases of the lexicon (not the dataset's own words),
each of which has a meaning. Two settings:

- *leave one out*: each word is taken out of the lexicon (``LEXICON.without(word)``)
  and looked up with what is left, as if the training had never held it;
- *held out*: the words of :func:`pgae_lite.freeform.phrase_lexicon.held_out_words`,
  looked up with the lexicon of ``PGAE-BERT-phrasings-held-out``.

A word is read *right* (replaced by a phrase of its own meaning), *wrong*
(another meaning) or *kept* (no single meaning: it stays as it is). Words of
the test paraphrases (``pgae_lite/freeform/paraphrases.tsv``) are left out of both
settings, so that the rule is chosen on words the test never says; the test
is read only to leave them out.
"""
import argparse
from collections import Counter

from pgae_lite.freeform.paraphrases import load_paraphrases
from pgae_lite.freeform.phrase_lexicon import LEXICON, SLOTS, held_out_words, training_lexicon, words_of
from pgae_lite.freeform.word_lookup import WordLookup
from pgae_lite.world.words import VOCABULARY

argparse.ArgumentParser(description=__doc__.splitlines()[0]).parse_args()   # no options: --help only
test_words = {w for p in load_paraphrases() for w in words_of(p.text)}
dataset_words = {w for word in VOCABULARY for w in words_of(word)}
meaning = {p: m for slot in SLOTS for m, phrases in LEXICON.phrases(slot).items() for p in phrases}
words = [p for p in meaning if len(words_of(p)) == 1 and p not in dataset_words and p not in test_words]


def read(lookup: WordLookup, word: str) -> tuple[str, str | None]:
    """(right, wrong, kept or known; the meaning the word was read as, if any)."""
    if lookup.is_known(word):
        return "known", None
    target = lookup.target(word)
    if target is None:
        return "kept", None
    read_as = lookup.meaning_of[target][1]
    return ("right" if read_as == meaning[word] else "wrong"), read_as


held, held_words = WordLookup(training_lexicon("held-out")), set(held_out_words())
settings = {"leave one out": {w: read(WordLookup(LEXICON.without(w)), w) for w in words},
            "held out": {w: read(held, w) for w in words if w in held_words}}
for name, reads in settings.items():
    counts = Counter(outcome for outcome, _ in reads.values())
    print(f"{name}: {len(reads)} words, " + ", ".join(f"{k} {counts[k]}" for k in ("right", "wrong", "kept", "known")))
    print("  wrong:", ", ".join(f"{w} ({meaning[w]} -> {read_as})" for w, (outcome, read_as) in reads.items()
                                if outcome == "wrong"))
    print("  kept:", ", ".join(f"{w} ({meaning[w]})" for w, (outcome, _) in reads.items() if outcome == "kept"))
