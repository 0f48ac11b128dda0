"""The language side of PGAE: vocabulary, synonyms, signals and descriptions.

Paper, Sec. 4 (Dataset) and Sec. 3 (Language Autoencoder). A description has
the grammar ``action colour speed``; every word has one synonym, so one
meaning has 2 x 2 x 2 = 8 equivalent descriptions. The vocabulary has 22
words plus ``<BOS/EOS>`` (23). Five signal phrases tell the model what to do;
they are appended as 5 extra input dimensions (23 + 5 = 28).

User text is parsed leniently (case, extra spaces, ``move up`` for
``move-up``); anything else raises :class:`LanguageError`, which names the
offending word and lists what is allowed.

A :class:`Lexicon` holds one vocabulary (words, synonyms, the grammar's slots);
:data:`DEFAULT_LEXICON` is the paper's, and the module constants below are its
parts. :meth:`Lexicon.with_colour` appends a colour word and its synonym (not
from the paper: the guided project "Teach NICO a new colour",
:mod:`pgae_lite.world.colours`); every function here takes ``lexicon=`` (default: the
paper's).
"""
from __future__ import annotations

import itertools
import re
from dataclasses import dataclass
from functools import cached_property

import torch

from pgae_lite.util.errors import PGAELiteError
from pgae_lite.world.typed import normalise_typed

BOS_EOS = "<BOS/EOS>"

#: The 23 output words, in the index order of the authors' ``vocabulary.txt``.
VOCABULARY: tuple[str, ...] = (
    BOS_EOS, "azure", "blonde", "blue", "cyan", "fast", "green", "greenish-blue",
    "harlequin", "move-down", "move-sideways", "move-up", "pull", "purple", "push",
    "quickly", "red", "scarlet", "slide", "slowly", "unhurriedly", "violet", "yellow",
)
WORD_INDEX: dict[str, int] = {w: i for i, w in enumerate(VOCABULARY)}

#: The five signals, in the index order of the authors' ``vocabulary.txt``.
SIGNALS: tuple[str, ...] = ("describe", "execute", "repeat action", "repeat both", "repeat language")
#: Signals used at test time (``repeat both`` is for training only).
TEST_SIGNALS: tuple[str, ...] = ("describe", "repeat language", "execute", "repeat action")

#: Input dimensions of the language encoder: 23 words + 5 signal tokens.
INPUT_DIM = len(VOCABULARY) + len(SIGNALS)

#: Each canonical word and its synonym (the paper's one-to-many mapping).
SYNONYMS: dict[str, str] = {
    "push": "move-up", "pull": "move-down", "slide": "move-sideways",
    "red": "scarlet", "green": "harlequin", "blue": "azure",
    "yellow": "blonde", "cyan": "greenish-blue", "violet": "purple",
    "slowly": "unhurriedly", "fast": "quickly",
}
ACTIONS: tuple[str, ...] = ("push", "pull", "slide")
COLOURS: tuple[str, ...] = ("red", "green", "blue", "yellow", "cyan", "violet")
SPEEDS: tuple[str, ...] = ("slowly", "fast")
#: The grammar: which canonical words may stand at each of the three positions.
SLOTS: tuple[tuple[str, ...], ...] = (ACTIONS, COLOURS, SPEEDS)
SLOT_NAMES: tuple[str, ...] = ("action", "colour", "speed")
#: Equivalent descriptions of one meaning: each of its three words or its synonym, 2 x 2 x 2.
DESCRIPTIONS = 2 ** len(SLOTS)

CANONICAL: dict[str, str] = {**{w: w for w in SYNONYMS}, **{s: w for w, s in SYNONYMS.items()}}

#: Inverse-frequency word weights of the weighted cross-entropy (authors' code).
WORD_WEIGHTS: dict[str, float] = {
    BOS_EOS: 0.1168, **{w: 1.4010 for c in COLOURS for w in (c, SYNONYMS[c])},
    **{w: 0.7005 for a in ACTIONS for w in (a, SYNONYMS[a])},
    **{w: 0.4670 for s in SPEEDS for w in (s, SYNONYMS[s])},
}


#: This module's error messages as templates (``str.format``, named fields); the page fills the same ones.
MESSAGES: dict[str, str] = {
    "unknown_signal": "unknown signal {signal}; the signals are: {signals}",
    "unknown_words": "unknown word{s} {words} in {text}; the vocabulary is: {vocabulary}",
    "description_length": "a description has 3 words (action colour speed), got {count} in {text}",
    "wrong_slot": "{word} cannot be the {slot} word in {text}; allowed: {allowed}",
}


class LanguageError(PGAELiteError, ValueError):
    """Bad user text or signal; the message says what was wrong and what is allowed."""


@dataclass(frozen=True)
class Lexicon:
    """A vocabulary: the output words in index order and the grammar's canonical words.

    ``synonyms`` holds (canonical word, synonym) pairs. A word's index is its
    one-hot dimension and its row in every trained weight, so an extended
    lexicon keeps the paper's 23 words in their order and appends new ones.
    """

    vocabulary: tuple[str, ...]
    synonyms: tuple[tuple[str, str], ...]
    actions: tuple[str, ...]
    colours: tuple[str, ...]
    speeds: tuple[str, ...]

    @cached_property
    def word_index(self) -> dict[str, int]:
        return {w: i for i, w in enumerate(self.vocabulary)}

    @cached_property
    def synonym(self) -> dict[str, str]:
        """Canonical word -> its synonym."""
        return dict(self.synonyms)

    @cached_property
    def canonical(self) -> dict[str, str]:
        """Any word -> its canonical word."""
        return {**{w: w for w, _ in self.synonyms}, **{s: w for w, s in self.synonyms}}

    @property
    def slots(self) -> tuple[tuple[str, ...], ...]:
        return (self.actions, self.colours, self.speeds)

    @property
    def size(self) -> int:
        """Number of output words (23 for the paper's)."""
        return len(self.vocabulary)

    @property
    def input_dim(self) -> int:
        """Input dimensions of the language encoder: the words + 5 signal tokens."""
        return self.size + len(SIGNALS)

    def word_weights(self) -> dict[str, float]:
        """Inverse-frequency weights (the authors' rule), mean 1, rounded to 4 digits.

        A word of a slot with n canonical words occurs in 1 of 2n descriptions,
        ``<BOS/EOS>`` in every one: weight ∝ 1 / frequency. For the paper's
        lexicon this gives the authors' table, :data:`WORD_WEIGHTS` (a test checks it).
        """
        inverse = {BOS_EOS: 1.0}
        for slot in self.slots:
            for c in slot:
                inverse.update({c: 2.0 * len(slot), self.synonym[c]: 2.0 * len(slot)})
        mean = sum(inverse[w] for w in self.vocabulary) / self.size
        return {w: round(inverse[w] / mean, 4) for w in self.vocabulary}

    def with_colour(self, name: str, synonym: str) -> "Lexicon":
        """This lexicon with a colour word and its synonym appended to the words."""
        for word, what in ((name, "colour"), (synonym, "synonym")):
            if not isinstance(word, str) or not re.fullmatch(r"[a-z]+(-[a-z]+)*", word):
                raise LanguageError(f"the {what} {word!r} must be one lowercase word "
                                    "(a hyphen joins two, as in greenish-blue)")
            if word in self.word_index or word in SIGNALS:
                raise LanguageError(f"the {what} {word!r} is already a word of the "
                                    f"vocabulary; the words are: "
                                    f"{', '.join(self.vocabulary[1:])}")
        if name == synonym:
            raise LanguageError(f"the synonym of {name!r} must be another word")
        return Lexicon(self.vocabulary + (name, synonym),
                       self.synonyms + ((name, synonym),),
                       self.actions, self.colours + (name,), self.speeds)


#: The paper's lexicon: the 23 words of the authors' ``vocabulary.txt``.
DEFAULT_LEXICON = Lexicon(VOCABULARY, tuple(SYNONYMS.items()), ACTIONS, COLOURS, SPEEDS)


def word_weights(lexicon: Lexicon | None = None) -> torch.Tensor:
    """The cross-entropy weights in vocabulary order, shape (23,) (or the lexicon's)."""
    if lexicon is None or lexicon == DEFAULT_LEXICON:
        return torch.tensor([WORD_WEIGHTS[w] for w in VOCABULARY])
    weights = lexicon.word_weights()
    return torch.tensor([weights[w] for w in lexicon.vocabulary])


def normalise_signal(signal: str) -> str:
    """Return the canonical signal name; accepts ``repeat_action``, ``Repeat Action:``…"""
    key = re.sub(r"[\s_:-]+", " ", str(signal)).strip().lower()
    if key not in SIGNALS:
        raise LanguageError(MESSAGES["unknown_signal"].format(signal=repr(signal), signals=", ".join(SIGNALS)))
    return key


def signal_index(signal: str) -> int:
    """Index of a signal among the 5 signal tokens (input dimension 23 + index)."""
    return SIGNALS.index(normalise_signal(signal))


def tokenize(text: str, lexicon: Lexicon | None = None) -> list[str]:
    """Split user text into vocabulary words, leniently.

    The text is read as :func:`~pgae_lite.world.typed.normalise_typed` gives it; case, punctuation and
    extra spaces are ignored and two-word synonyms may be
    written with a space (``move up``, ``greenish blue``). Unknown words raise
    :class:`LanguageError` naming every one of them and listing the vocabulary.
    """
    if not isinstance(text, str):
        raise LanguageError(f"the text must be a string, e.g. 'push red slowly'; got "
                            f"{type(text).__name__} {text!r:.80}")
    lex = lexicon or DEFAULT_LEXICON
    words = re.sub(r"[.,;:!?]", " ", normalise_typed(text).lower().replace(BOS_EOS.lower(), " ")).split()
    tokens: list[str] = []
    unknown: list[str] = []
    i = 0
    while i < len(words):
        pair = "-".join(words[i:i + 2])
        if i + 1 < len(words) and pair in lex.word_index:
            tokens.append(pair)
            i += 2
        else:
            (tokens if words[i] in lex.word_index else unknown).append(words[i])
            i += 1
    if unknown:
        vocab = ", ".join(sorted(w for w in lex.vocabulary if w != BOS_EOS))
        listed = ", ".join(repr(w) for w in dict.fromkeys(unknown))
        raise LanguageError(MESSAGES["unknown_words"].format(s="s" if len(set(unknown)) > 1 else "", words=listed,
                                                             text=repr(text), vocabulary=vocab))
    return tokens


def parse_description(text: str, lexicon: Lexicon | None = None) -> tuple[str, str, str]:
    """Parse ``action colour speed`` into canonical words, e.g. ``('push', 'red', 'fast')``.

    Raises :class:`LanguageError` for unknown words, a wrong length or a word in
    the wrong position (the message says which word each position allows).
    """
    lex = lexicon or DEFAULT_LEXICON
    tokens = tokenize(text, lex)
    if len(tokens) != 3:
        raise LanguageError(MESSAGES["description_length"].format(count=str(len(tokens)), text=repr(text)))
    canon = []
    for token, slot, name in zip(tokens, lex.slots, SLOT_NAMES):
        word = lex.canonical.get(token)
        if word not in slot:
            allowed = ", ".join(w2 for w in slot for w2 in (w, lex.synonym[w]))
            raise LanguageError(MESSAGES["wrong_slot"].format(word=repr(token), slot=name, text=repr(text),
                                                              allowed=allowed))
        canon.append(word)
    return tuple(canon)  # type: ignore[return-value]


def equivalent_descriptions(action: str, colour: str, speed: str,
                            lexicon: Lexicon | None = None) -> list[tuple[str, str, str]]:
    """The 8 equivalent descriptions of one meaning (each word or its synonym).

    Order follows the authors' data: canonical first, the action word's
    synonym varying fastest, then the colour's, then the speed's.
    """
    lex = lexicon or DEFAULT_LEXICON
    words = parse_description(f"{action} {colour} {speed}", lex)
    choices = [(w, lex.synonym[w]) for w in reversed(words)]   # speed, colour, action
    return [tuple(reversed(c)) for c in itertools.product(*choices)]


def encode(words: tuple[str, ...] | list[str], lexicon: Lexicon | None = None) -> torch.Tensor:
    """Word list -> index tensor with ``<BOS/EOS>`` at both ends, shape (len + 2,).

    The words are vocabulary words as written (``move-up``, not ``move up``); a string,
    or any other word, raises :class:`LanguageError` (:func:`tokenize` splits text).
    """
    lex = lexicon or DEFAULT_LEXICON
    if not isinstance(words, (list, tuple)):
        raise LanguageError(f"encode takes a list of vocabulary words, e.g. "
                            f"['push', 'red', 'slowly']; got {type(words).__name__} "
                            f"{words!r:.80} (tokenize(text) splits text into words)")
    for position, word in enumerate(words):
        if not isinstance(word, str) or word not in lex.word_index or word == BOS_EOS:
            vocab = ", ".join(w for w in lex.vocabulary if w != BOS_EOS)
            raise LanguageError(f"encode got {word!r:.80} at position {position}, not "
                                f"a word of the vocabulary: {vocab}")
    return torch.tensor([0] + [lex.word_index[w] for w in words] + [0])


def one_hot(indices: torch.Tensor, dim: int = len(VOCABULARY)) -> torch.Tensor:
    """Indices (...,) -> one-hot float vectors (..., dim); an index outside 0 to dim-1 is a LanguageError."""
    t = torch.as_tensor(indices)
    if t.is_floating_point() or t.is_complex() or t.dtype == torch.bool or bool(((t < 0) | (t >= dim)).any()):
        raise LanguageError(f"one_hot takes word indices, whole numbers 0-{dim - 1} (the vocabulary's {dim} words); "
                            f"got {t.dtype} values {t.flatten()[:8].tolist()}")
    return torch.nn.functional.one_hot(t.long(), dim).float()


def decode(indices: torch.Tensor | list[int], lexicon: Lexicon | None = None) -> str:
    """Generated word indices (or one-hot / probability rows) -> text.

    Reading stops at the first ``<BOS/EOS>``, so an output of ``<EOS>`` alone gives ``""``.
    Anything else (an index outside 0-22, a fraction, text, rows of another width)
    raises :class:`LanguageError` naming it.
    """
    vocabulary = (lexicon or DEFAULT_LEXICON).vocabulary
    t = _word_indices(indices, len(vocabulary))
    words = []
    for i in t.tolist():
        if i == 0:
            break
        words.append(vocabulary[i])
    return " ".join(words)


def _chosen(scores: torch.Tensor, wanted: str) -> torch.Tensor:
    """The word each row of scores (steps, n) chooses, read up to the first <BOS/EOS>; a row that is not
    finite, or whose highest score is shared (no word chosen: an all-zero row), is a LanguageError."""
    if scores.is_floating_point() and not torch.isfinite(scores).all():
        row = int((~torch.isfinite(scores)).any(-1).nonzero()[0])
        raise LanguageError(f"{wanted}; row {row} holds a value that is not finite (NaN or infinite)")
    chosen = scores.argmax(-1)
    ends = (chosen == 0).nonzero().flatten()
    read = scores[: int(ends[0]) + 1 if len(ends) else len(scores)]          # the rows that are read
    shared = ((read == read.max(-1, keepdim=True).values).sum(-1) > 1).nonzero().flatten()
    if len(shared):
        raise LanguageError(f"{wanted}; row {int(shared[0])} chooses no word (its highest score is shared by "
                            "several words, e.g. a row of zeros)")
    return chosen


def _word_indices(indices, n: int) -> torch.Tensor:
    """:func:`decode`'s input checked: 1-D integer indices 0 to n-1 (n words), or a LanguageError."""
    wanted = (f"decode takes word indices (whole numbers 0-{n - 1}) or rows of "
              f"{n} scores (steps, {n})")
    if isinstance(indices, (str, bytes)):
        raise LanguageError(f"{wanted}; got the text {indices!r:.80} "
                            "(parse_description reads text)")
    if isinstance(indices, (list, tuple)) and any(isinstance(i, bool) for i in indices):
        raise LanguageError(f"{wanted}; got {indices!r:.80}, with True or False in it")
    try:
        t = torch.as_tensor(indices)
    except (TypeError, ValueError, RuntimeError, OverflowError):
        raise LanguageError(f"{wanted}; got {indices!r:.80}") from None
    if t.dim() == 2 and t.shape[1] == n and t.dtype != torch.bool and not t.is_complex():
        return _chosen(t, wanted)       # (steps, words) one-hot or probabilities
    if t.dim() != 1 or t.dtype == torch.bool or t.is_complex():
        raise LanguageError(f"{wanted}; got {t.dim()}-D {t.dtype} of shape "
                            f"{tuple(t.shape)}")
    bad = ((t < 0) | (t >= n) | (t != t.round())).nonzero().flatten()
    if len(bad):
        i = int(bad[0])
        raise LanguageError(f"{wanted}; got {t[i].item()} at position {i}")
    return t.long()


def is_correct(generated: str, alternatives: list[tuple[str, ...]] | None) -> bool:
    """Paper's criterion: every word matches one of the equivalent descriptions.

    ``alternatives=None`` means the expected output is ``<EOS>`` alone (empty text).
    """
    if not isinstance(generated, str):
        raise LanguageError(f"is_correct compares a generated text (a string, '' for <EOS> alone); "
                            f"got {generated!r}")
    if alternatives is None:
        return generated == ""
    return tuple(generated.split()) in {tuple(a) for a in alternatives}
