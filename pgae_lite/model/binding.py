"""The binding loss of PRAE and PVAE: paired codes together, unpaired ones a margin apart.

PGAE paper, Sec. 2 (related work): PRAE (Yamada et al., RA-L 2018) "consists of independent
action and language networks and uses a binding loss to align the hidden representations of
the paired actions and descriptions"; PVAE keeps it, on the means of its codes. With
``z_L`` the description codes and ``z_A`` the action codes of a batch of B pairs (row i of
each belongs to sample i), and ``D[i, j] = ||z_A[i] - z_L[j]||``::

    L_bind = mean_i D[i, i]                                           # paired codes together
           + 1/B^2 sum_{i != j} max(0, m + D[j, j] - D[i, j])         # description j: its own action
           + 1/B^2 sum_{i != j} max(0, m + D[i, i] - D[i, j])         # action i: its own description

each unpaired code at least the margin ``m`` (1 in the authors' code) farther than the paired one.
The 1/B^2 counts the diagonal's zeros, as the authors' mean over the whole B x B matrix does.
"""
from __future__ import annotations

import torch

from pgae_lite.util.errors import ArgumentError


def binding_loss(z_language: torch.Tensor, z_action: torch.Tensor, margin: float = 1.0) -> torch.Tensor:
    """``L_bind`` of a batch of paired codes, ``z_language`` and ``z_action`` both (B, D); see the module."""
    if z_language.dim() != 2 or z_language.shape != z_action.shape:
        raise ArgumentError(f"the binding loss takes two (batch, dimension) tensors of one shape, row i of "
                            f"each from sample i; got {tuple(z_language.shape)} and {tuple(z_action.shape)}")
    if not margin >= 0:
        raise ArgumentError(f"the binding loss's margin must be a number >= 0; got {margin!r}")
    batch = z_language.shape[0]
    distance = torch.cdist(z_action, z_language)                 # D[i, j] = ||z_A[i] - z_L[j]||, (B, B)
    paired = distance.diagonal()                                 # D[i, i], (B,)
    unpaired = 1.0 - torch.eye(batch, device=distance.device)    # 0 on the diagonal
    language_side = torch.relu(margin + paired[None, :] - distance) * unpaired   # m + D[j, j] - D[i, j]
    action_side = torch.relu(margin + paired[:, None] - distance) * unpaired     # m + D[i, i] - D[i, j]
    return paired.mean() + language_side.mean() + action_side.mean()


__all__ = ["binding_loss"]
