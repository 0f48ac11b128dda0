"""The plan head: h must say where the arm will go (not in the paper; the book recipe's).

In the paper's ``execute`` (Sec. 3, Action Autoencoder) the action decoder
reads the *recorded* frames at every step. Those frames show the arm on its
way to the right cube, so the shared representation h never has to say which
cube the instruction means in this scene: the binding of the instruction's
colour ("red") to a side of the table (red lies on the left) can be read off
the pictures a few steps into the motion. Measured on our data, a linear probe
cannot tell the side from h of a model trained the paper's way, and in closed
loop, where the pictures are the robot's own, most failures move the other
cube (chapter 07; the book's results page).

The plan head makes h carry the plan. A small network reads h and predicts K
keyframes of the motion, and its error joins the loss:

    plan   = W_2 tanh(W_1 h + b_1) + b_2                         (B, K x 5)
    target = mean over the training recordings of the sample's pattern of
             their joints at K evenly spaced steps (step 0 to the last)
    L_plan = mean over keyframes and joints of (plan - target)²
    L      = α L_lang + β (L_act + γ L_plan)                     (γ = TrainConfig.plan_weight)

The target is the pattern's mean, not the sample's own joints: what the first
frame and the words determine is the motion the instruction means, not the
random variation of one recording (on the authors' data the six recordings of
a pattern differ by about 7% of the joint range). Only the signals whose
action target is the whole motion take part (execute, repeat action, repeat
both); the head is used in training only and never feeds the decoders.
"""
from __future__ import annotations

import torch
from torch import nn

from .data import JOINT_DIM
from .signals import EXECUTE, REPEAT_ACTION, REPEAT_BOTH

#: The signals whose action target is the whole motion: their h must carry the plan.
PLAN_SIGNALS = (EXECUTE, REPEAT_ACTION, REPEAT_BOTH)


class PlanHead(nn.Module):
    """h (B, hidden) -> K keyframes of the planned motion, flattened (B, K x 5), model units."""

    def __init__(self, hidden: int, keyframes: int, units: int = 100):
        super().__init__()
        self.keyframes = keyframes
        self.net = nn.Sequential(nn.Linear(hidden, units), nn.Tanh(),   # tanh(W_1 h + b_1)
                                 nn.Linear(units, keyframes * JOINT_DIM))  # W_2 · + b_2

    def forward(self, h: torch.Tensor) -> torch.Tensor:
        return self.net(h)


def keyframe_steps(lengths: torch.Tensor, keyframes: int) -> torch.Tensor:
    """K evenly spaced steps of each sample, from 0 to its last, (N,) -> (N, K)."""
    share = torch.linspace(0.0, 1.0, keyframes, device=lengths.device)
    return (share[None] * (lengths[:, None] - 1).float()).round().long()


def plan_targets(joints: torch.Tensor, lengths: torch.Tensor, patterns: torch.Tensor,
                 keyframes: int) -> torch.Tensor:
    """Each sample's target: its pattern's mean keyframes over the given samples, (N, K x 5).

    ``joints`` (N, T, 5) in model units, ``lengths`` (N,), ``patterns`` (N,) pattern numbers.
    """
    steps = keyframe_steps(lengths, keyframes)                           # (N, K)
    keys = torch.gather(joints, 1, steps[..., None].expand(-1, -1, joints.shape[2]))  # (N, K, 5)
    keys = keys.reshape(len(joints), -1)                                 # (N, K x 5)
    groups, which = torch.unique(patterns, return_inverse=True)          # which: (N,) group of each sample
    sums = keys.new_zeros(len(groups), keys.shape[1]).index_add_(0, which, keys)
    counts = torch.bincount(which, minlength=len(groups)).to(keys)[:, None]
    return (sums / counts)[which]                                        # the pattern's mean, per sample


def plan_loss(plan: torch.Tensor, target: torch.Tensor, signal: torch.Tensor) -> torch.Tensor:
    """L_plan over the samples whose signal is in :data:`PLAN_SIGNALS` (0 when there are none)."""
    rows = torch.isin(signal, torch.tensor(PLAN_SIGNALS, device=signal.device))
    if not rows.any():
        return plan.new_zeros(())
    return ((plan[rows] - target[rows]) ** 2).mean()
