"""The pretrained encoder with its top layer tuned on every input: PVAE-BERT's fine-tuning, at the top layer.

PGAE paper, Sec. 3 ("Language Autoencoder", last paragraph) keeps PGAE-BERT's transformer frozen;
PVAE-BERT (Özdemir et al., IEEE TCDS 2022) fine-tunes the whole of BERT-base and mean-pools its
tokens. Deviation from paper (PVAE-BERT's): only the top layer of the transformer this project
ships is tuned (:class:`~pgae_lite.bert.tuned_layer.TunedTopLayer`, the same layer the free-form
variant tunes), and every input reads it, the dataset's own descriptions included. The layers below
stay frozen, so for each of the 869 fixed inputs the top layer's input x is computed once and cached
on disk, and a step runs the top layer alone on its batch's rows. With x_1..x_T the top layer's
input over one text's real tokens::

    y_1..y_T = TopLayer(x_1..x_T)           the tuned layer (tuned_layer.py's two blocks)
    f        = 1/T Σ_t y_t                  (D,), the mean over real tokens, as PVAE-BERT pools

In training, the top layer learns from one call in :data:`~pgae_lite.bert.tuned_layer.TRAIN_EVERY`
and runs forward only on the others, as the free-form variant's does, without weight decay, at
:data:`TUNED_LR_SCALE` of the recipe's rate: a tenth of the free-form variant's rate, at which this
layer lost what the words say (chosen on our data's training split, ``benchmarks/tuned_rate.py``). Deviation
from paper (PVAE-BERT's tunes all along): the encoder tunes it in the first :data:`TUNED_SHARE` of a
training's steps (:meth:`TunedPretrainedEncoder.at_step`), then calls :meth:`TunedPretrainedEncoder.stop_learning`,
and the 869 inputs' f are computed once and read from a table. Tuned to the end, PVAE-BERT-tuned
took more than 1.5x PGAE's recipe time, the book's budget for a family model (seed 0,
``results/family_length_batches.json``, against PGAE in ``results/family-original.json``).
"""
from __future__ import annotations

import torch
from torch import nn

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
from pgae_lite.bert.tuned_layer import LR_SCALE, TRAIN_EVERY, TopLayerHead, TunedTopLayer
from pgae_lite.model.language import LanguageEncoderBase

#: The share of a training's steps in which the top layer learns (see the module).
TUNED_SHARE = 1 / 3
#: The top layer's rate, a fraction of the recipe's: the free-form variant's LR_SCALE / 10. Chosen by
#: benchmarks/tuned_rate.py on the training split of our data (results/tuned_rate.json), never on a test set.
TUNED_LR_SCALE = LR_SCALE / 10


def mean_over_tokens(states: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
    """Token vectors (B, T, D) and their mask (B, T) -> the mean over real tokens (B, D)."""
    weight = mask[..., None].to(states.dtype)                        # (B, T, 1)
    return (states * weight).sum(1) / weight.sum(1)                  # f = 1/T Σ_t y_t


class TunedPretrainedEncoder(LanguageEncoderBase):
    """Frozen transformer below its top layer -> the tuned top layer -> mean over tokens -> (B, output_dim).

    Called like PGAE-BERT's :class:`~pgae_lite.bert.pretrained.PretrainedLanguageEncoder`: ``lang_tokens``
    rows in ``forward``, any text in :meth:`encode_texts`. The transformer stays outside the module tree
    (frozen, in no optimiser); ``top``, a copy of its top layer, is the only trained part.
    """

    pooling = "mean"
    reads_free_text = True

    def __init__(self, name: str | None = None):
        super().__init__()
        self.name = model_name(name)
        self.output_dim = int(self.transformer.model.config.hidden_size)
        self.texts, row_of_code = fixed_inputs()
        states, mask = cached_token_vectors(self.transformer, self.texts, "fixed", top_input=True)
        self.register_buffer("states", states, persistent=False)             # (869, T, D): the top layer's input
        self.register_buffer("mask", mask, persistent=False)                 # (869, T)
        self.register_buffer("row_of_code", row_of_code, persistent=False)   # (5·23³,)
        self.top = TunedTopLayer(self.transformer)
        self.top.lr_scale = TUNED_LR_SCALE           # its optimiser group's rate (train.optimiser.parameter_groups)
        self.calls = 0                                                       # training calls, for TRAIN_EVERY
        self.table: torch.Tensor | None = None       # f of the 869 inputs, once stop_learning is called

    @property
    def transformer(self) -> Transformer:
        """The loaded tokenizer and model (loaded on first use in this process)."""
        return load_transformer(self.name)

    def export_head(self) -> nn.Module:
        """The page's head: the tuned top layer, then the mean over the tokens."""
        return TopLayerHead(self.top)

    def at_step(self, step: int, steps: int) -> None:
        """The top layer learns in the first :data:`TUNED_SHARE` of the ``steps``; from then on (a resumed or a
        finished training: ``at_step(steps, steps)``, and a loaded model), f of the fixed inputs is read from
        a table (:meth:`stop_learning`)."""
        if step >= round(TUNED_SHARE * steps) and self.table is None:
            self.stop_learning()

    @torch.no_grad()
    def stop_learning(self) -> None:
        """The top layer learns no more: f of the 869 fixed inputs is computed once (without dropout) and read
        from a table from now on, so no gradient reaches the layer (it still counts among the trained
        parameters); free text still runs the top layer, without recording gradients."""
        training, self.table = self.top.training, None
        self.top.eval()
        self.table = torch.cat([self.pool(self.states[i:i + 128], self.mask[i:i + 128])
                                for i in range(0, len(self.texts), 128)])                      # (869, D)
        self.top.train(training)

    def pool(self, states: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
        """The top layer's input (B, T, D) and mask (B, T) -> f (B, D), through the tuned layer."""
        device = self.mask.device
        states, mask = states.to(device, torch.float32), mask.to(device)
        longest = int(mask.any(0).nonzero().max()) + 1                       # drop columns of padding only
        states, mask = states[:, :longest], mask[:, :longest]                # (B, T', D), (B, T')
        learn = self.training and torch.is_grad_enabled() and self.table is None      # None: still learning
        if learn:
            learn, self.calls = self.calls % TRAIN_EVERY == 0, self.calls + 1
        with torch.set_grad_enabled(learn):
            return mean_over_tokens(self.top(states, mask), mask)

    def encode_texts(self, texts: list[str]) -> torch.Tensor:
        """Any texts -> f (B, output_dim), the signal phrase first: ``["repeat both push the red one"]``."""
        texts = check_texts("encode_texts", texts)
        return self.pool(*padded_token_vectors(self.transformer, texts, top_input=True))

    def forward(self, tokens: torch.Tensor, lengths: torch.Tensor | None = None) -> torch.Tensor:
        """``lang_tokens`` (B, 5) -> (B, output_dim); rows outside the fixed 869 run the frozen layers first.

        ``lengths`` is not needed (a row's text ends at its first <EOS>); it is accepted so that every
        language encoder is called the same way."""
        rows = table_rows(check_token_ids(tokens), self.row_of_code).to(self.mask.device)
        missing = (rows < 0).nonzero().flatten()
        if not len(missing):
            return self.pool(self.states[rows], self.mask[rows]) if self.table is None else self.table[rows]
        texts = [tokens_to_text(row) for row in tokens.cpu()]
        return self.encode_texts(texts)

    def extra_repr(self) -> str:
        return f"{self.name!r}, pooling='mean', top layer tuned on every input"


__all__ = ["TUNED_LR_SCALE", "TUNED_SHARE", "TunedPretrainedEncoder", "mean_over_tokens"]
