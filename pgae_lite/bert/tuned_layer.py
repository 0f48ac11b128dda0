"""Fine-tuning the transformer's top layer for free text (not in the paper).

Paper, Sec. 3 ("Language Autoencoder", last paragraph): PGAE-BERT keeps its
pretrained transformer frozen; the authors found that fine-tuning it made Table 1
worse. Deviation from paper: the free-form variant ``PGAE-BERT-phrasings`` tunes
the top (last) of its layers, for free text only. A BERT-style layer is two
blocks, each with a residual connection and a layer normalisation (LN):

    h = LN_1(x + W_O · Attention(W_Q x, W_K x, W_V x))      self-attention block
    y = LN_2(h + W_2 · GELU(W_1 h + b_1) + b_2)              feed-forward block

Both are trained, starting from the pretrained weights, at a small learning
rate and without weight decay (:data:`LR_SCALE`). Every layer below stays
frozen, so the top layer's input x is computed once per text and cached on disk
(the phrasings' bank); a training step runs the top layer alone on the few
samples that read a phrasing, and learns from them in one step of
:data:`TRAIN_EVERY` (forward only on the others). The 869 fixed inputs (the dataset's own
descriptions) keep the frozen layer's output, cached as in PGAE-BERT: the tuned
layer learns only from, and is only used for, free text.

Chosen on validation sentences with words never trained on
(``experiments/validation_readback.py``; experiments/HISTORY.md).
"""
from __future__ import annotations

import math

import torch
from torch import nn

from pgae_lite.bert.transformer import Transformer

#: The tuned layer learns from the phrasings of one training step in TRAIN_EVERY, and runs forward only
#: (a third of the cost) on the others, so that the variant's training stays within 1.5x PGAE-BERT's.
TRAIN_EVERY = 3
#: Learning rate of the tuned layer, as a fraction of the recipe's (TrainConfig.lr), no weight decay:
#: a hundredth for each step it learns from. Deviation from paper (which tunes nothing): chosen on
#: validation sentences, never on the test set.
LR_SCALE = 0.01 * TRAIN_EVERY

_PARTS = ("attention.self.query", "attention.self.key", "attention.self.value", "attention.output.dense",
          "attention.output.LayerNorm", "intermediate.dense", "output.dense", "output.LayerNorm")


def top_layer(tf: Transformer) -> nn.Module:
    """The transformer's last layer, checked to be BERT-style (MiniLM, BERT)."""
    layers = getattr(getattr(tf.model, "encoder", None), "layer", None)
    if layers is None or not all(_part(layers[-1], p) is not None for p in _PARTS):
        raise ValueError(f"tuned_top_layer needs a BERT-style transformer (encoder.layer[-1] with "
                         f"{', '.join(_PARTS)}), as MiniLM and BERT are; {tf.name!r} is "
                         f"{type(tf.model).__name__}. Use it with tuned_top_layer=False.")
    if getattr(tf.model.config, "hidden_act", "gelu") != "gelu":
        raise ValueError(f"tuned_top_layer needs a GELU feed-forward block; {tf.name!r} uses "
                         f"{tf.model.config.hidden_act!r}")
    return layers[-1]


def _part(module: nn.Module | None, path: str) -> nn.Module | None:
    for name in path.split("."):
        module = getattr(module, name, None)
    return module


class TunedTopLayer(nn.Module):
    """The top layer, trained: x (B, T, D) with mask (B, T) -> y (B, T, D)."""

    lr_scale = LR_SCALE   # train.py gives these weights their own group: lr · lr_scale, no weight decay

    def __init__(self, tf: Transformer):
        super().__init__()
        layer, cfg = top_layer(tf), tf.model.config
        self.heads = int(cfg.num_attention_heads)
        names = dict(zip(("query", "key", "value", "attended", "norm_1", "inner", "outer", "norm_2"), _PARTS))
        for mine, path in names.items():     # our own copies: the shared transformer stays frozen
            theirs = _part(layer, path)
            copy = (nn.LayerNorm(theirs.normalized_shape, eps=theirs.eps) if isinstance(theirs, nn.LayerNorm)
                    else nn.Linear(theirs.in_features, theirs.out_features))
            copy.load_state_dict(theirs.state_dict())                  # start from the pretrained weights
            self.add_module(mine, copy)
        self.attention_dropout = nn.Dropout(float(getattr(cfg, "attention_probs_dropout_prob", 0.1)))
        self.dropout = nn.Dropout(float(getattr(cfg, "hidden_dropout_prob", 0.1)))   # the model's own

    def forward(self, x: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
        B, T, D = x.shape
        q, k, v = (f(x).view(B, T, self.heads, D // self.heads).transpose(1, 2)    # (B, H, T, D/H) each
                   for f in (self.query, self.key, self.value))
        scores = q @ k.transpose(-1, -2) / math.sqrt(D // self.heads)             # Q K^T / sqrt(d), (B, H, T, T)
        weights = self.attention_dropout(scores.masked_fill(~mask[:, None, None, :], float("-inf")).softmax(-1))
        attended = (weights @ v).transpose(1, 2).reshape(B, T, D)                  # heads side by side, (B, T, D)
        h = self.norm_1(x + self.dropout(self.attended(attended)))                 # h = LN_1(x + W_O · Attention)
        inner = nn.functional.gelu(self.inner(h))                                  # GELU(W_1 h + b_1), (B, T, 4D)
        return self.norm_2(h + self.dropout(self.outer(inner)))                    # y = LN_2(h + W_2 · ... + b_2)


class TopLayerHead(nn.Module):
    """A pretrained encoder's features from the token vectors below the transformer's top layer, for one text
    without padding (what the reader's page runs, :mod:`pgae_lite.web.sentence`): the top layer (tuned, or a
    copy of the pretrained one), then the encoder's pooling, the mean over the tokens or ``attention``."""

    def __init__(self, top: TunedTopLayer, attention: nn.Module | None = None):
        super().__init__()
        self.top, self.attention = top.eval(), attention

    def forward(self, below_top: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
        last = self.top(below_top, mask.bool())                             # (1, L, D), the top layer
        if self.attention is None:                                          # the paper's: the mean
            weight = mask[..., None].float()                                # (1, L, 1)
            return (last * weight).sum(1) / weight.sum(1)                   # f = Σ_t x_t / L
        return self.attention(last, mask.bool())                            # f = 1/K Σ_k Σ_t a_tk x_t


__all__ = ["LR_SCALE", "TRAIN_EVERY", "TopLayerHead", "TunedTopLayer", "top_layer"]
