"""Attention pooling over the frozen transformer's token vectors (not in the paper).

Paper, Sec. 3 ("Language Autoencoder", last paragraph): PGAE-BERT reads its input
with a frozen pretrained transformer and feeds the GMU one sentence vector, the
mean of the token vectors (:mod:`pgae_lite.bert.pretrained`). In a free-form
instruction most tokens are frame and carrier words (``could you please ...``):
the mean dilutes the few that say action, colour and speed. This encoder keeps
the transformer frozen and learns where to look. With K heads over the token
vectors x_1..x_T of one input (padding excluded):

    a_tk = softmax_t(w_k · x_t + b_k)          attention of head k over the tokens
    f    = 1/K Σ_k Σ_t a_tk x_t                 (D,), into the GMU as PGAE-BERT's f

w and b start at zero, so at the start of training every head weighs the real
tokens equally and f is PGAE-BERT's mean-pooled vector. The K·(D+1) weights are
the encoder's only trained parameters. As in PGAE-BERT, the token vectors of the
869 inputs the vocabulary allows are computed once and cached on disk; any other
text runs through the transformer. With ``tuned=True`` (ModelConfig.tuned_top_layer),
free text, any text outside the 869, reads the transformer's top layer trained
(:mod:`pgae_lite.bert.tuned_layer`) before the pooling. A training on phrasings gives
the encoder its ``word_lookup`` (:meth:`AttentivePretrainedEncoder.learn_words`,
:mod:`pgae_lite.freeform.word_lookup`): free text's words that training never held are first
looked up in WordNet. ``ModelConfig(language=AttentionConfig(tuned_top_layer=True))`` builds it:
the free-form variant ``PGAE-BERT-phrasings`` (:mod:`pgae_lite.runs.rows`), never the paper's PGAE-BERT.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import torch
from torch import nn

from pgae_lite.bert.config import PretrainedConfig, check_words
from pgae_lite.bert.pretrained import (
    Transformer,
    cached_token_vectors,
    check_texts,
    check_token_ids,
    fixed_inputs,
    load_transformer,
    model_name,
    padded_token_vectors,
    table_rows,
    tokens_to_text,
)
from pgae_lite.bert.tuned_layer import TopLayerHead, TunedTopLayer
from pgae_lite.freeform.word_lookup import WordLookup
from pgae_lite.model.language import LanguageEncoderBase
from pgae_lite.world.words import DEFAULT_LEXICON, Lexicon

#: Attention heads (K). Deviation from paper: chosen on generated validation sentences
#: (experiments/validation_readback.py's grammar seed), never on the test paraphrases.
HEADS = 4


class AttentionPooling(nn.Module):
    """Token vectors (B, T, D) and their mask (B, T) -> f (B, D), K heads averaged."""

    def __init__(self, dim: int, heads: int = HEADS):
        super().__init__()
        self.score = nn.Linear(dim, heads)                           # w_k, b_k for k = 1..K
        nn.init.zeros_(self.score.weight)                            # uniform attention: the mean at start
        nn.init.zeros_(self.score.bias)

    def forward(self, states: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
        scores = self.score(states).masked_fill(~mask[..., None], float("-inf"))   # (B, T, K)
        a = scores.softmax(dim=1)                                    # a_tk = softmax_t(w_k · x_t + b_k)
        return torch.einsum("btk,btd->bd", a, states) / a.shape[-1]  # f = 1/K Σ_k Σ_t a_tk x_t


@dataclass(frozen=True)
class AttentionConfig(PretrainedConfig):
    """The free-form variant's encoder (``ModelConfig.language``): PGAE-BERT's settings (the transformer ``model``,
    None for the default the project ships), its tokens read through a trained attention pooling; with
    ``tuned_top_layer``, free text reads the transformer's top layer tuned."""

    kind: ClassVar[str] = "pretrained-attention"

    def build(self, lexicon: Lexicon = DEFAULT_LEXICON) -> LanguageEncoderBase:
        """The encoder these settings describe, for a model of ``lexicon``'s words (the paper's)."""
        check_words(lexicon)
        return AttentivePretrainedEncoder(self.model, tuned=self.tuned_top_layer)


class AttentivePretrainedEncoder(LanguageEncoderBase):
    """Frozen pretrained transformer -> token vectors -> trained attention pooling -> (B, output_dim).

    Called like PGAE-BERT's :class:`~pgae_lite.bert.pretrained.PretrainedLanguageEncoder`:
    ``lang_tokens`` rows in ``forward``, any text in :meth:`encode_texts`. The transformer
    stays outside the module tree (frozen, in no optimiser); the pooling is trained, and
    with ``tuned`` so is the transformer's top layer for free text (``top``).
    """

    pooling = "attention"
    reads_free_text = True

    def __init__(self, name: str | None = None, heads: int = HEADS, tuned: bool = False):
        super().__init__()
        self.name = model_name(name)
        self.output_dim = int(self.transformer.model.config.hidden_size)
        self.texts, row_of_code = fixed_inputs()
        states, mask = cached_token_vectors(self.transformer, self.texts, "fixed")
        self.register_buffer("states", states, persistent=False)             # (869, T, D)
        self.register_buffer("mask", mask, persistent=False)                 # (869, T)
        self.register_buffer("row_of_code", row_of_code, persistent=False)   # (5·23³,)
        self.attention = AttentionPooling(self.output_dim, heads)
        # free text only: the top layer, trained (tuned_layer.py); None = frozen
        self.top = TunedTopLayer(self.transformer) if tuned else None
        self._row_of_text = {text: i for i, text in enumerate(self.texts)}
        # learnt with a training on phrasings (learn_words), saved with the weights (get_extra_state):
        # free text's unknown words looked up first (word_lookup.py)
        self.word_lookup: WordLookup | None = None
        # a text it was trained on (a description, e.g. said back) reads the frozen layer's output, as in training
        self.fixed_from_table = tuned

    def learn_words(self, lexicon, sentences: list[str]) -> None:
        """Know the words of a training's phrasings: ``lexicon``'s phrases and the ``sentences`` themselves; free
        text's other words are looked up in WordNet first (:class:`~pgae_lite.freeform.word_lookup.WordLookup`)."""
        self.word_lookup = WordLookup(lexicon, sentences)

    def export_head(self) -> nn.Module:
        """The page's head: the top layer (tuned, or a copy of the pretrained one), then the attention pooling."""
        return TopLayerHead(self.top if self.top is not None else TunedTopLayer(self.transformer), self.attention)

    def get_extra_state(self) -> dict:
        """Saved in the state dict beside the weights: the word lookup, as plain strings."""
        return {"word_lookup": None if self.word_lookup is None else self.word_lookup.state()}

    def set_extra_state(self, state: dict) -> None:
        """A loaded model reads free text as the trained one did: with the same word lookup."""
        saved = state.get("word_lookup") if isinstance(state, dict) else None
        self.word_lookup = None if saved is None else WordLookup.from_state(saved)

    @property
    def transformer(self) -> Transformer:
        """The loaded tokenizer and model (loaded on first use in this process)."""
        return load_transformer(self.name)

    def pool(self, states: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
        """Token vectors (B, T, D) and mask (B, T) -> f (B, D) on this encoder's device."""
        device = self.mask.device
        return self.attention(states.to(device, torch.float32), mask.to(device))

    def free_text_vectors(self, texts: list[str], what: str | None = None,
                          dtype: torch.dtype = torch.float32) -> tuple[torch.Tensor, torch.Tensor]:
        """Texts outside the 869 -> what :meth:`pool_free_text` reads, (B, T, D) and (B, T), on the CPU:
        the frozen transformer's output, or with ``top`` the top layer's input. ``what``: kept on disk."""
        tuned = self.top is not None
        if what is None:
            return padded_token_vectors(self.transformer, texts, top_input=tuned)
        return cached_token_vectors(self.transformer, texts, what, dtype, top_input=tuned)

    def pool_free_text(self, states: torch.Tensor, mask: torch.Tensor, train_top: bool = True) -> torch.Tensor:
        """:meth:`free_text_vectors` (B, T, D), (B, T) -> f (B, D), through ``top`` if tuned.

        ``train_top=False``: ``top`` runs without recording gradients (the attention pooling still learns)."""
        if self.top is not None:
            device = self.mask.device
            states, mask = states.to(device, torch.float32), mask.to(device)
            longest = int(mask.any(0).nonzero().max()) + 1                   # drop columns of padding only
            states, mask = states[:, :longest], mask[:, :longest]            # (B, T', D), (B, T')
            with torch.set_grad_enabled(train_top and torch.is_grad_enabled()):
                states = self.top(states, mask)                              # (B, T', D)
        return self.pool(states, mask)

    def read_as(self, text: str) -> str:
        """The text as this encoder reads it: with its word lookup, unknown words replaced."""
        # Deviation from paper: unknown words looked up in WordNet first ("amethyst cube" -> "purple cube")
        return text if self.word_lookup is None else self.word_lookup.rewrite(text)

    def encode_texts(self, texts: list[str]) -> torch.Tensor:
        """Any texts -> f (B, output_dim), the signal phrase first: ``["execute push the red one"]``.

        Each text is read as :meth:`read_as` gives it (the lookup's rewrite changes a text once: the
        words it puts in are training words)."""
        texts = [self.read_as(text) for text in check_texts("encode_texts", texts)]
        if self.top is None:
            return self.pool(*padded_token_vectors(self.transformer, texts))
        # a fixed input (a description, e.g. said back) reads the frozen layer's output, as in training
        fixed = [k for k, text in enumerate(texts) if text in self._row_of_text]
        free = [k for k, text in enumerate(texts) if text not in self._row_of_text]
        out = torch.empty(len(texts), self.output_dim, device=self.mask.device)
        if fixed:
            rows = torch.tensor([self._row_of_text[texts[k]] for k in fixed], device=self.mask.device)
            out[fixed] = self.pool(self.states[rows], self.mask[rows])
        if free:
            out[free] = self.pool_free_text(*self.free_text_vectors([texts[k] for k in free]))
        return out

    def forward(self, tokens: torch.Tensor, lengths: torch.Tensor | None = None) -> torch.Tensor:
        """``lang_tokens`` (B, 5) -> (B, output_dim); rows outside the fixed 869 run the transformer."""
        rows = table_rows(check_token_ids(tokens), self.row_of_code).to(self.mask.device)
        known = rows.clamp(min=0)
        out = self.pool(self.states[known], self.mask[known])
        missing = (rows < 0).nonzero().flatten()
        if len(missing):
            out = out.index_put((missing,), self.encode_texts(
                [tokens_to_text(tokens[i]) for i in missing.tolist()]))
        return out

    def extra_repr(self) -> str:
        tuned = "top layer tuned for free text" if self.top is not None else "transformer frozen"
        return f"{self.name!r}, pooling='attention', output_dim={self.output_dim}, {tuned}"


__all__ = ["AttentionConfig", "AttentionPooling", "AttentivePretrainedEncoder", "HEADS"]
