"""The loss PGAE learns from, and the optimiser's rate (paper Sec. 3, "Loss Function"; Sec. 4).

    L = α · weighted cross-entropy(words) + β · MSE(joints)

The word weights counter word frequency (``<BOS/EOS>`` is in every
description, a colour word in one of six); both terms are averaged over the
valid steps only.
"""
from __future__ import annotations

import math

import torch
from torch import nn

from pgae_lite.data.dataset import JOINT_DIM
from pgae_lite.model.signals import SignalBatch


def pgae_loss(out: dict[str, torch.Tensor], batch: SignalBatch, weights: torch.Tensor,
              alpha: float = 1.0, beta: float = 1.0) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """Total, language and action loss of one batch.

    language = Σ w[y] · CE(logits, y) / Σ mask  over valid words
    action   = Σ (ĵ − j)² / (5 · Σ mask)        over valid steps
    """
    ce = nn.functional.cross_entropy(out["logits"].transpose(1, 2), batch.lang_target,
                                     reduction="none")                      # (B, 4)
    m = batch.lang_mask.float()
    lang = (weights[batch.lang_target] * ce * m).sum() / m.sum()
    jm = batch.joint_mask.float()[..., None]                                # (B, T-1, 1)
    act = ((out["joints"] - batch.joint_target) ** 2 * jm).sum() / (jm.sum() * out["joints"].shape[-1])
    return alpha * lang + beta * act, lang, act


def lr_factor(step: int, total: int, warmup: float, schedule: str) -> float:
    """Learning-rate multiplier: linear warm-up, then cosine decay to 0 (or constant)."""
    warm = int(warmup * total)
    if step < warm:
        return (step + 1) / warm
    if schedule == "constant":
        return 1.0
    progress = (step - warm) / max(1, total - warm)
    return 0.5 * (1.0 + math.cos(math.pi * min(1.0, progress)))


def parameter_groups(model: nn.Module) -> list[dict]:
    """The optimiser's groups: every weight at the recipe's rate, except those of a module with an
    ``lr_scale`` (the tuned top layer, tuned_layer.py): lr · lr_scale, no weight decay."""
    scaled = [m for m in model.modules() if hasattr(m, "lr_scale")]
    own = {id(p) for m in scaled for p in m.parameters()}
    groups = [{"params": [p for p in model.parameters() if id(p) not in own], "lr_scale": 1.0}]
    groups += [{"params": list(m.parameters()), "lr_scale": m.lr_scale, "weight_decay": 0.0} for m in scaled]
    return groups


def add_input_noise(action_input: torch.Tensor, std: float, joint_std: float | None = None) -> torch.Tensor:
    """``action_input`` (B, T, 30 + 5) plus Gaussian noise: ``std`` on the visual features, ``joint_std``
    on the joints (``None``: ``std`` on both)."""
    noise = torch.randn_like(action_input)
    if joint_std is None:
        return action_input + std * noise
    scale = torch.full((action_input.shape[-1],), std, device=action_input.device)
    scale[-JOINT_DIM:] = joint_std                                        # the last 5 channels are joints
    return action_input + scale * noise


__all__ = ["add_input_noise", "lr_factor", "parameter_groups", "pgae_loss"]
