"""The optimiser: its parameter groups and its rate over the steps (paper Sec. 4, "Training Details").

Paper, Sec. 4: Adam at a constant rate of 10^-5. Deviation from paper: the book's recipe warms up
linearly and then decays the rate on a cosine (``TrainConfig.schedule``); a module that asks for a
rate of its own (``lr_scale``: the tuned top layer of the transformer) gets its own group.
"""
from __future__ import annotations

import math

from torch import nn


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
    ``lr_scale`` (the tuned top layer, bert/tuned_layer.py): lr · lr_scale, no weight decay."""
    scaled = [m for m in model.modules() if hasattr(m, "lr_scale")]
    own = {id(p) for m in scaled for p in m.parameters()}
    groups = [{"params": [p for p in model.parameters() if id(p) not in own], "lr_scale": 1.0}]
    groups += [{"params": list(m.parameters()), "lr_scale": m.lr_scale, "weight_decay": 0.0} for m in scaled]
    return groups


__all__ = ["lr_factor", "parameter_groups"]
