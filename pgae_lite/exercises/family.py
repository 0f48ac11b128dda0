"""Checks of the family chapter's exercises: the binding loss of PRAE and PVAE (PGAE paper, Sec. 2).

``check_binding_loss(my_binding_loss)`` runs the student's loss next to
:func:`pgae_lite.model.binding.binding_loss` on seeded random codes, at several margins, and
names a known mistake when one reproduces the student's numbers (chapter 09).
"""
from __future__ import annotations

from typing import Callable

import torch

from pgae_lite.exercises.result import RAISED, CheckResult, _call, _compare
from pgae_lite.model.binding import binding_loss
from pgae_lite.util.checks import MAX_SEED, whole_number

BINDING_EQUATION = ("L = mean_i D[i,i] + 1/B² Σ_{i≠j} [max(0, m + D[j,j] − D[i,j]) + max(0, m + D[i,i] − D[i,j])], "
                    "D[i,j] = ||z_A[i] − z_L[j]||")


def _variant(z_language, z_action, margin, pull=True, squared=False, sides=2, over_pairs=False):
    """The binding loss with switches that reproduce common mistakes."""
    d = torch.cdist(z_action, z_language) ** (2 if squared else 1)
    b, paired = len(d), d.diagonal()
    off = 1.0 - torch.eye(b, dtype=d.dtype)
    scale = 1.0 / (b * (b - 1)) if over_pairs else 1.0 / b ** 2
    language = (torch.relu(margin + paired[None, :] - d) * off).sum() * scale
    action = (torch.relu(margin + paired[:, None] - d) * off).sum() * scale
    return (paired.mean() if pull else 0.0) + action + (language if sides == 2 else 0.0)


MISTAKES = {
    "the pull term mean_i D[i,i] is missing": dict(pull=False),
    "the distances are squared; the binding loss uses the distances themselves": dict(squared=True),
    "only the action side is there: each description must also be nearer its own action (m + D[j,j] − D[i,j])":
        dict(sides=1),
    "the push terms are averaged over the B(B−1) unpaired pairs; the authors average over all B² entries":
        dict(over_pairs=True),
}


@torch.random.fork_rng(devices=[])
def check_binding_loss(student: Callable, seed: int = 0) -> CheckResult:
    """``student(z_language, z_action, margin)`` -> the binding loss (a 0-d tensor), against the package's."""
    result = CheckResult("check_binding_loss")
    gen = torch.Generator().manual_seed(whole_number("seed", seed, 0, MAX_SEED))
    for margin in (1.0, 0.0, 2.5):
        z_language, z_action = (torch.randn(6, 4, generator=gen, dtype=torch.float64) for _ in range(2))
        got = _call(result, f"your loss at margin {margin}", student, z_language.clone(), z_action.clone(), margin)
        if got is RAISED:
            return result
        expected = binding_loss(z_language, z_action, margin)
        if not _compare(result, f"the loss at margin {margin}", got, expected):
            for mistake, switches in MISTAKES.items():
                if torch.allclose(torch.as_tensor(got, dtype=torch.float64),
                                  torch.as_tensor(_variant(z_language, z_action, margin, **switches),
                                                  dtype=torch.float64), atol=1e-6):
                    return result.fail(f"it matches a known mistake: {mistake}", BINDING_EQUATION)
            return result.fail("no known mistake reproduces it", BINDING_EQUATION)
    return result


__all__ = ["BINDING_EQUATION", "check_binding_loss"]
