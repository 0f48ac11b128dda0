"""The plan head: h must say where the arm will go (not in the paper; the book recipe's).

In the paper's ``execute`` (Sec. 3, Action Autoencoder) the action decoder
reads the *recorded* frames at every step. Those frames show the arm on its
way to the right cube, so the shared representation h never has to say which
cube the instruction means in this scene: the binding of the instruction's
colour ("red") to a side of the table (red lies on the left) can be read off
the pictures a few steps into the motion. Measured on our data, a linear probe
reads the side from h of a model trained the paper's way little better than a
coin, and in closed loop, where the pictures are the robot's own, most failures
move the other cube (chapter 07; the book's results page).

The plan head makes h carry the plan. A small network reads h and predicts K
keyframes of the motion, and its error joins the loss::

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

from pgae_lite.data.dataset import JOINT_DIM, PGAEDataset
from pgae_lite.data.normaliser import Normaliser
from pgae_lite.model.signals import EXECUTE, REPEAT_ACTION, REPEAT_BOTH, make_batch, signal_ids
from pgae_lite.world.patterns import Pattern
from pgae_lite.world.words import DESCRIPTIONS

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


@torch.no_grad()
def execute_representations(model: nn.Module, data: PGAEDataset, normaliser: Normaliser) -> torch.Tensor:
    """h of every sample of ``data`` under ``execute`` (its description i mod 8, first step), (N, hidden)."""
    model.eval()
    device = next(model.parameters()).device
    tensors = normaliser.tensors(data, device)
    index = torch.arange(len(data))
    batch = make_batch(tensors, index, signal_ids("execute", len(data)), index % DESCRIPTIONS)
    return model.encode(batch)[0].cpu()


def probe_accuracy(x: torch.Tensor, y: torch.Tensor, x_test: torch.Tensor, y_test: torch.Tensor,
                   steps: int = 200) -> float:
    """Test accuracy (%) of logistic regression fitted on (x (N, D), y (N,) of 0/1), on (x_test, y_test)."""
    mean, std = x.mean(0), x.std(0) + 1e-6
    probe = nn.Linear(x.shape[1], 1)
    optimiser = torch.optim.LBFGS(probe.parameters(), max_iter=steps, line_search_fn="strong_wolfe")

    def closure():
        optimiser.zero_grad()
        loss = nn.functional.binary_cross_entropy_with_logits(probe((x - mean) / std)[:, 0], y.float())
        loss = loss + 1e-3 * probe.weight.pow(2).sum()                     # a little L2: separable data
        loss.backward()
        return loss

    with torch.enable_grad():
        optimiser.step(closure)
    with torch.no_grad():
        said = probe((x_test - mean) / std)[:, 0] > 0
    return 100 * float((said == y_test.bool()).float().mean())


def which_cube_probe(model: nn.Module, data: PGAEDataset, normaliser: Normaliser) -> float:
    """Does h say which cube to move? A linear probe's test accuracy (%), left cube or right.

    The probe (:func:`probe_accuracy`), on h under ``execute`` (:func:`execute_representations`),
    is fitted on the training split and scored on the test split, whose scenes pair colours
    and actions as no training sample did. 50% is chance.
    """
    def side(split: PGAEDataset) -> torch.Tensor:                        # 1 = the left cube
        return torch.tensor([int(Pattern.from_number(int(p)).side == "L") for p in split.pattern])

    train, test = data.split("train"), data.split("test")
    return probe_accuracy(execute_representations(model, train, normaliser), side(train),
                          execute_representations(model, test, normaliser), side(test))
