"""A language adapter: a trained residual MLP on the frozen encoder's sentence vector (not in the paper).

PGAE-BERT (paper Sec. 3, "Language Autoencoder", last paragraph) feeds the frozen
transformer's sentence vector straight into the GMU, whose language candidate is
one linear map of it, L_h = tanh(W_L f + b). Trained on many ways of saying each
instruction (:mod:`pgae_lite.phrasing_bank`), a linear map can only draw straight
boundaries through the transformer's sentence space, where "shove it away" and
"pull it closer" may lie side by side. The adapter bends that space before the
GMU, while the transformer stays frozen:

    f' = f + W_2 GELU(W_1 LayerNorm(f) + b_1) + b_2          (B, D) -> (B, D)

W_2 and b_2 start at zero, so an untrained adapter passes f through unchanged.
Used by the variant ``PGAE-BERT-adapter`` (:data:`pgae_lite.config.TRAININGS`),
not by the paper's PGAE-BERT.
"""
from __future__ import annotations

import torch
from torch import nn


class LanguageAdapter(nn.Module):
    """f (B, D) -> f + MLP(LayerNorm(f)), an MLP of ``hidden`` units; the identity when untrained."""

    def __init__(self, dim: int, hidden: int):
        super().__init__()
        self.norm = nn.LayerNorm(dim)
        self.inner = nn.Linear(dim, hidden)                 # W_1, b_1
        self.outer = nn.Linear(hidden, dim)                 # W_2, b_2
        nn.init.zeros_(self.outer.weight)
        nn.init.zeros_(self.outer.bias)

    def forward(self, f: torch.Tensor) -> torch.Tensor:
        return f + self.outer(nn.functional.gelu(self.inner(self.norm(f))))   # f + W_2 GELU(W_1 LN(f) + b_1) + b_2
