"""Training PGAE-BERT on instructions said in many ways (not in the paper).

Paper, Sec. 3: PGAE-BERT's pretrained encoder "has the potential to recognise
unseen natural language", but trained on the dataset's three-word descriptions
alone it reads a free-form instruction as something far from anything it was
trained on. With ``TrainConfig.phrasings`` = :class:`PhrasingsConfig` (K per meaning), every
sample whose signal takes a description (execute, repeat both, repeat language; or those of
its ``signals``) reads, with probability ``prob``, one of K sentences that say its
description in other words (:func:`pgae_lite.freeform.phrasings.phrasings`, a grammar
and lexicon written for the purpose, independent of the held-out test
sentences) instead of the description itself. The targets stay the dataset's
words. The transformer stays frozen (up to its top layer, when that is tuned:
:mod:`pgae_lite.bert.tuned_layer`): the K sentences of each meaning and reading
signal are encoded once (``S x 36 x K`` sentences for S signals) and kept on
disk like its table of fixed inputs. A training step then adds only what comes
after the cache for the picked sentences: a lookup of their sentence vectors
for the mean; for the attention pooling (:mod:`pgae_lite.freeform.attention_pooling`)
the trained attention over their cached token vectors, and before it the tuned
top layer, if there is one, over the cached input of that layer.
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass
from functools import lru_cache
from typing import ClassVar

import torch

from pgae_lite.bert.pretrained import input_text
from pgae_lite.bert.tuned_layer import TRAIN_EVERY
from pgae_lite.freeform.attention_pooling import AttentivePretrainedEncoder
from pgae_lite.freeform.phrase_lexicon import PHRASING_WORDS, PhraseLexicon, training_lexicon
from pgae_lite.freeform.phrasings import phrasings, phrasings_digest
from pgae_lite.model.config import Part, whole
from pgae_lite.model.signals import LANG_IN, SignalBatch
from pgae_lite.util.storage import CorruptCheckpointError, cache_dir, config_digest, load_torch, save_torch
from pgae_lite.world.words import CANONICAL, SIGNALS, SLOTS, VOCABULARY

MEANINGS = tuple(itertools.product(*SLOTS))                       # 36 (action, colour, speed)
TEXT_SIGNALS = tuple(s for s in range(len(SIGNALS)) if LANG_IN[s])   # execute, repeat both, repeat language
#: The signals that take a description, and so may read phrasings (PhrasingsConfig.signals).
PHRASING_SIGNALS = tuple(SIGNALS[s] for s in TEXT_SIGNALS)


@dataclass(frozen=True)
class PhrasingsConfig(Part):
    """A training on phrasings (``TrainConfig.phrasings``): ``per_meaning`` sentences K of every instruction, read
    with probability ``prob`` by the samples of ``signals``; ``words``: "all" of the lexicon, or "held-out",
    less :func:`~pgae_lite.freeform.phrase_lexicon.held_out_words` (see the module)."""

    kind: ClassVar[str] = "phrasings"
    slot: ClassVar[str] = "phrasings"
    per_meaning: int = 60
    # Chosen on generated validation sentences (experiments/validation_readback.py), never on the test
    # paraphrases (experiments/HISTORY.md).
    prob: float = 0.75
    words: str = "all"
    signals: tuple[str, ...] = PHRASING_SIGNALS

    def __post_init__(self):
        whole("PhrasingsConfig", "per_meaning", self.per_meaning, 1)
        if isinstance(self.prob, bool) or not isinstance(self.prob, (int, float)) or not 0 < self.prob <= 1:
            raise ValueError(f"PhrasingsConfig prob must be a number in (0, 1], the chance that a sample with a "
                             f"description reads a phrasing instead; got {self.prob!r}")
        if self.words not in PHRASING_WORDS:
            raise ValueError(f"PhrasingsConfig words must be one of {', '.join(PHRASING_WORDS)}; got {self.words!r}")
        signals = tuple(self.signals) if isinstance(self.signals, (list, tuple)) else ()
        if not signals or not set(signals) <= set(PHRASING_SIGNALS):
            raise ValueError(f"PhrasingsConfig signals must name one or more of {', '.join(PHRASING_SIGNALS)}; "
                             f"got {self.signals!r}")
        object.__setattr__(self, "signals", signals)

    def to_dict(self) -> dict:
        """Its settings, and which sentences its grammar and lexicon give (a digest of those of seed 0): an edited
        grammar or lexicon changes the recipe, so a model trained on other sentences is never reused."""
        return super().to_dict() | {"sentences": _sentences_digest(self.per_meaning, self.words)}


@lru_cache(maxsize=8)
def _sentences_digest(per_meaning: int, words: str) -> str:
    return phrasings_digest(per_meaning, 0, training_lexicon(words))


class PhrasingBank:
    """Sentence vectors of K phrasings per (reading signal, meaning): a tensor (S, 36, K, D), S <= 3."""

    def __init__(self, encoder: torch.nn.Module, per_meaning: int, seed: int = 0,
                 lexicon: PhraseLexicon | None = None, signals: tuple[str, ...] | None = None,
                 prob: float = 0.75):   # 0.75: PhrasingsConfig.prob's default
        if not encoder.reads_free_text:
            raise ValueError("phrasings need a pretrained language encoder (ModelConfig."
                             "language=PretrainedConfig() or AttentionConfig()); this model has "
                             f"{type(encoder).__name__}")
        self.per_meaning, self.encoder, self.prob = per_meaning, encoder, prob
        # only the signals that read phrasings are encoded (the others' rows would never be read)
        self.signals = tuple(s for s in TEXT_SIGNALS if signals is None or SIGNALS[s] in signals)
        self.texts = [input_text(SIGNALS[s], text) for s in self.signals for m in MEANINGS
                      for text in phrasings(*m, per_meaning, seed=seed, lexicon=lexicon)]
        shape = (len(self.signals), len(MEANINGS), per_meaning)
        device = next(encoder.buffers()).device
        if isinstance(encoder, AttentivePretrainedEncoder):
            # token vectors, pooled by the trained attention at every step; float16 halves their memory
            states, mask = encoder.free_text_vectors(self.texts, "phrasings", torch.float16)
            self.states = states.reshape(*shape, *states.shape[1:]).to(device)   # (S, 36, K, T, D)
            self.mask = mask.reshape(*shape, -1).to(device)                       # (S, 36, K, T)
        else:
            key = config_digest({"texts": self.texts, "encoder": encoder.transformer.digest,
                                 "pooling": encoder.pooling})
            path = cache_dir() / "embeddings" / f"phrasings-{key}.pt"
            vectors = None
            if path.exists():
                try:            # the checks every saved file gets, the vectors finite
                    vectors = load_torch(path, ("vectors",), what="phrasing cache", finite=("vectors",))["vectors"]
                except CorruptCheckpointError:          # damaged: computed again, never trusted
                    vectors = None
            if not isinstance(vectors, torch.Tensor) or vectors.dim() != 2 or len(vectors) != len(self.texts):
                vectors = encoder._run_transformer(self.texts)          # (S·36·K, D), once
                save_torch({"vectors": vectors}, path)
            self.vectors = vectors.reshape(*shape, -1).to(device)        # (S, 36, K, D)
        # input token -> its canonical word's position in its slot (-1: not a description word)
        self.slot_index = torch.full((len(VOCABULARY),), -1, dtype=torch.long)
        for word, canonical in CANONICAL.items():
            slot = next(slot for slot in SLOTS if canonical in slot)
            self.slot_index[VOCABULARY.index(word)] = slot.index(canonical)
        # signal -> its row in the bank (-1: the signal reads no phrasings)
        self.signal_row = torch.full((len(SIGNALS),), -1, dtype=torch.long)
        for row, s in enumerate(self.signals):
            self.signal_row[s] = row

    def meanings(self, tokens: torch.Tensor) -> torch.Tensor:
        """``lang_tokens`` (B, 5) with a description -> meaning index 0..35 (B,)."""
        a, c, s = self.slot_index[tokens[:, 1:4].cpu()].unbind(1)         # each (B,)
        return (a * len(SLOTS[1]) + c) * len(SLOTS[2]) + s

    def features(self, model: torch.nn.Module, batch: SignalBatch,
                 generator: torch.Generator, step: int = 0) -> torch.Tensor:
        """The language features of a training batch (B, D): phrasings for some samples.

        ``step``: the training step (from 0), which says whether a tuned top layer learns in it."""
        base = model.language_encoder(batch.lang_tokens, batch.lang_lengths)
        size = len(batch.signal)
        row = self.signal_row[batch.signal.cpu()]                            # (B,), -1: no description
        takes = (row >= 0) & (torch.rand(size, generator=generator) < self.prob)
        which = torch.randint(self.per_meaning, (size,), generator=generator)
        if not takes.any():
            return base
        rows = takes.nonzero().flatten()
        meaning = self.meanings(batch.lang_tokens[rows])
        pick = (row[rows], meaning, which[rows])
        if isinstance(self.encoder, AttentivePretrainedEncoder):
            # a tuned top layer learns from the phrasings of one step in TRAIN_EVERY (forward only on the others)
            said = self.encoder.pool_free_text(self.states[pick], self.mask[pick],    # trained: gradients flow
                                               train_top=(step + 1) % TRAIN_EVERY == 0)
        else:
            said = self.vectors[pick]
        return base.index_put((rows.to(base.device),), said)


def for_training(model: torch.nn.Module, config: PhrasingsConfig, seed: int) -> PhrasingBank:
    """The bank a training on phrasings (``config``, the recipe's ``seed``) reads its language from: what the
    caller hands the training loop (:func:`pgae_lite.train.loop.train`'s ``language``) for ``model``.

    The free-form variant's encoder learns the words of the same lexicon and sentences (its word lookup,
    :meth:`~pgae_lite.freeform.attention_pooling.AttentivePretrainedEncoder.learn_words`), saved with its weights.
    """
    encoder = model.language_encoder
    lexicon = training_lexicon(config.words)
    bank = PhrasingBank(encoder, config.per_meaning, seed, lexicon, config.signals, config.prob)
    if isinstance(encoder, AttentivePretrainedEncoder):       # words never trained on: WordNet first
        encoder.learn_words(lexicon, bank.texts)
    return bank
