"""Checks of the acting chapter's exercises: Table 1's nRMSE, the tracking target, pictures that come late.

Paper, Sec. 4 ("Results": the joint error nRMSE = sqrt(MSE) / range of Table 1) and our closed
loop (chapter 07, :mod:`pgae_lite.robot.closedloop`, not in the paper): the motor target that
brings the measured joints to the model's ĵ_t in one recorded step, and the decoder reading its
frames k steps late. Each check runs a student's function next to the package's on seeded inputs
(:func:`pgae_lite.evaluate.table1.joint_nrmse`; the simulator itself for the tracking target)
and names a known mistake when one reproduces the student's numbers.
"""
from __future__ import annotations

import math
from typing import Any, Callable

import numpy as np
import torch

from pgae_lite.evaluate.table1 import joint_nrmse
from pgae_lite.exercises.result import RAISED, CheckResult, _call, _compare, _diagnose, _numbers, _unchanged
from pgae_lite.sim.record import SimConfig, shared_simulation
from pgae_lite.sim.robot import HOME_POSE
from pgae_lite.util.checks import MAX_SEED, whole_number

NRMSE_EQUATION = ("nRMSE = 100 · sqrt(mean over every episode's steps 1..length−1 and the 5 joints of (ĵ − j)²) "
                  "/ joint_range, one pooled mean over all episodes")
TRACKING_EQUATION = "u = q + (ĵ − q) / α, α = 1 − (1 − gain)^substeps"
DELAY_RULE = "out[b, t] = vision[b, min(max(t − k, 0), steps[b] − 1)]"


def _close(got: float, expected: float) -> bool:
    return math.isclose(got, expected, rel_tol=1e-6, abs_tol=1e-9)


# ------------------------------------------------------------------ Table 1's nRMSE
def _episodes(seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """Six seeded episodes (6, 20, 5): predicted and recorded joints, zero-padded past their lengths (20 or 10)."""
    rng = np.random.default_rng(whole_number("seed", seed, 0, MAX_SEED))
    lengths = np.array([20, 10, 20, 10, 10, 20])
    target = np.cumsum(rng.normal(0, 0.05, (6, 20, 5)), axis=1) + rng.uniform(-1, 1, (1, 1, 5))
    scale = rng.uniform(0.005, 0.05, (6, 1, 1))                        # a different error per episode
    joints = target + rng.normal(0, 1, target.shape) * scale
    joints[:, 0] = target[:, 0]                                        # step 0: the given start pose
    padding = np.arange(20)[None, :, None] >= lengths[:, None, None]   # (6, 20, 1)
    target, joints = np.where(padding, 0.0, target), np.where(padding, 0.0, joints)
    return joints, target, lengths, 2.5


def _nrmse_variant(joints, target, lengths, joint_range, first=1, padded=False, root=True, percent=True,
                   per_episode=False, own_range=False) -> float:
    """Table 1's nRMSE with switches that reproduce common mistakes."""
    valid = np.arange(joints.shape[1])[None] < lengths[:, None]                # (N, T)
    steps = valid.copy()
    steps[:, :first] = False                                                   # step 0 is given, not predicted
    if own_range:
        joint_range = float(target[valid].max() - target[valid].min())
    sq = ((joints - target) ** 2).mean(-1)                                     # (N, T), mean over the 5 joints

    def one(mask: np.ndarray) -> float:
        mse = sq[mask].mean() if not padded else sq[:, first:].mean()
        return (math.sqrt(mse) if root else mse) / joint_range * (100 if percent else 1)
    if per_episode:
        return float(np.mean([one(np.eye(len(sq), dtype=bool)[i][:, None] & steps) for i in range(len(sq))]))
    return one(steps)


def check_nrmse(student: Callable, seed: int = 0) -> CheckResult:
    """``student(joints, target, lengths, joint_range) -> float``: Table 1's joint error in %, against
    :func:`~pgae_lite.evaluate.table1.joint_nrmse` (its first value, over the valid steps).

    ``joints`` and ``target`` are (N, T, 5) numpy arrays, zero past each episode's length
    ``lengths[i]``; step 0 is the given start pose (the same in both); ``joint_range`` is the
    dataset's observed range of joint values (``data.joint_range()``).
    """
    result = CheckResult("Table 1's nRMSE")
    joints, target, lengths, joint_range = _episodes(seed)
    result.note(f"input: 6 episodes {joints.shape}, lengths {lengths.tolist()}, joint_range {joint_range}")
    valid = (np.arange(joints.shape[1])[None] < lengths[:, None])[..., None]
    expected = joint_nrmse(np.where(valid, joints, np.nan), np.where(valid, target, np.nan), joint_range)[0]
    given = {"joints": joints.copy(), "target": target.copy(), "lengths": lengths.copy()}
    out = _call(result, "your nRMSE", student, *given.values(), joint_range)
    if out is RAISED:
        return result
    if out is None:
        return result.fail("your nRMSE returned None; expected one number, in %",
                           "a stub returns None: end with return the nRMSE")
    if isinstance(out, (torch.Tensor, np.ndarray)):
        if (out.numel() if isinstance(out, torch.Tensor) else out.size) != 1:
            return result.fail(f"your nRMSE has shape {tuple(out.shape)}; expected one number for all the "
                               "episodes", "pool the squared errors of every episode's valid steps, then take one root")
        out = out.item()
    number = _numbers(result, [out], "your nRMSE")
    if number is None:
        return result
    kept = {"joints": joints, "target": target, "lengths": lengths}
    for name, array in kept.items():
        if not np.array_equal(given[name], array):
            result.fail(f"your nRMSE changed {name} in place", "compute new arrays (no +=, no slice assignment)")
    got = number[0]
    if _close(got, expected) and result:
        return result.ok(f"{got:.4f}% over the valid predicted steps, as Table 1's (the reference: {expected:.4f}%)")
    result.fail(f"your nRMSE is {got:.6g}; expected {expected:.6g} (%)")
    mistakes = {
        "you averaged over every step of the padded arrays (the authors' padded convention): "
        "Table 1's nRMSE averages each episode's valid steps 1..length−1 only": dict(padded=True),
        "step 0 is the given start pose, not a prediction: count steps 1..length−1": dict(first=0),
        "nRMSE is in %: multiply by 100": dict(percent=False),
        "RMSE: take the square root of the mean squared error": dict(root=False),
        "you averaged the episodes' own nRMSEs; Table 1 pools the squared errors of all valid steps, "
        "then takes one root": dict(per_episode=True),
        "divide by the joint_range you are given (the whole dataset's, data.joint_range()), "
        "not the range of these targets": dict(own_range=True),
    }
    args = (joints, target, lengths, joint_range)
    hint = next((h for h, switches in mistakes.items() if _close(got, _nrmse_variant(*args, **switches))), None)
    return result.note(f"diagnosis: {hint}" if hint else f"compare each term with the equation: {NRMSE_EQUATION}")


# ------------------------------------------------------------------ the tracking target
def _reached(target: np.ndarray, seed: int) -> tuple[float, float]:
    """One recorded step of the simulator with motor target ``target``: how far the measured joints end from
    the desired ones, and how far sending the desired joints themselves ends (both rad, the largest joint)."""
    sim = shared_simulation(SimConfig())
    errors = []
    for sent in ("student", "desired"):
        sim.reset(0, 0, seed % 1000, render=False)
        sim.step(np.array(HOME_POSE), render=False)                   # step 0, as every recording
        q = sim.joints()
        desired = q + np.random.default_rng(seed).uniform(-0.05, 0.05, 5)
        sim.step(target(q, desired) if sent == "student" else desired, render=False)
        errors.append(float(np.abs(sim.joints() - desired).max()))
    return errors[0], errors[1]


def check_tracking_target(student: Callable, seed: int = 0) -> CheckResult:
    """``student(q, desired, gain, substeps) -> u``: the motor target (5,) that brings the measured joints
    ``q`` (5,) to ``desired`` (5,) in one recorded step, when each of its ``substeps`` physics steps closes
    the share ``gain`` of the gap (pybullet's position motor: gain 0.1, 3 substeps). The closed loop's
    tracking (:mod:`pgae_lite.robot.closedloop`); the check also runs it in the simulator.
    """
    result = CheckResult("tracking target")
    rng = np.random.default_rng(whole_number("seed", seed, 0, MAX_SEED))
    for gain, substeps in ((0.1, 3), (0.2, 2), (0.1, 1)):
        q = rng.uniform(-1, 1, 5)
        desired = q + rng.uniform(-0.1, 0.1, 5)
        alpha = 1 - (1 - gain) ** substeps                            # share of the gap closed in one step
        expected = torch.from_numpy(q + (desired - q) / alpha)        # u = q + (ĵ − q) / α
        given = {"q": q.copy(), "desired": desired.copy()}
        out = _call(result, f"your target(gain={gain}, substeps={substeps})", student, *given.values(), gain, substeps)
        if out is RAISED:
            return result
        if out is None:
            return result.fail("your target returned None; expected 5 numbers (a numpy array)",
                               "a stub returns None: end with return u")
        try:
            got = torch.as_tensor(np.asarray(out, dtype=np.float64))
        except (TypeError, ValueError):
            return result.fail(f"your target returned {out!r:.60}; expected 5 numbers (a numpy array)")
        if any(not np.array_equal(given[k], v) for k, v in (("q", q), ("desired", desired))):
            return result.fail("your target changed q or desired in place", "compute a new array")
        if _compare(result, f"u (gain {gain}, {substeps} substeps)", got, expected):
            continue
        variant = lambda a: torch.from_numpy(q + (desired - q) / a)  # noqa: E731 - the same rule with another α
        _diagnose(result, [got], [
            ("no tracking: the motor closes only a share α of the gap in one step; send q + (ĵ − q) / α",
             [torch.from_numpy(desired)]),
            ("α is the share closed in one recorded STEP, 1 − (1 − gain)^substeps, not the gain of one substep",
             [variant(gain)]),
            ("each substep closes a share of what is LEFT: α = 1 − (1 − gain)^substeps, not substeps × gain",
             [variant(gain * substeps)]),
            ("(1 − gain)^substeps is the share left OPEN after a step; α = 1 − (1 − gain)^substeps",
             [variant((1 - gain) ** substeps)]),
            ("divide the gap by α, do not multiply: a motor that closes α of it needs a target 1/α as far",
             [torch.from_numpy(q + (desired - q) * alpha)]),
            ("start from the MEASURED joints q: u = q + (ĵ − q) / α, not ĵ + ...",
             [torch.from_numpy(desired + (desired - q) / alpha)]),
        ], TRACKING_EQUATION)
        return result
    run = _call(result, "your target in the simulator", _reached,
                lambda q, d: np.asarray(student(q, d, 0.1, SimConfig().substeps), dtype=np.float64), seed)
    if run is RAISED:
        return result
    reached, untracked = run
    return result.ok(f"in the simulator the arm ends {reached:.1e} rad from ĵ after one step "
                     f"(sending ĵ itself: {untracked:.3f} rad)")


# ------------------------------------------------------------------ pictures that come late
def delayed_vision(vision: torch.Tensor, k: int, steps: torch.Tensor) -> torch.Tensor:
    """``vision`` (B, S, D) read ``k`` steps late: step t reads frame t − k, within each sample's ``steps``
    frames (the first frame while t < k, the last real one past the end; k < 0: frames that lead).

    Chapter 07's exercise "Pictures that come late" (not in the paper)."""
    t = torch.arange(vision.shape[1], device=vision.device)
    index = (t[None] - k).clamp(min=0).minimum(steps[:, None] - 1)            # (B, S)
    return vision.gather(1, index[..., None].expand_as(vision))


def check_delayed(student: Callable, seed: int = 0) -> CheckResult:
    """``student(vision, k, steps) -> vision`` (B, S, 30) read ``k`` steps late, against :func:`delayed_vision`
    at k = 0, 2, −3 (frames that lead) and 40 (longer than any episode: the first frame held). Only each
    sample's real steps (t < steps[b]) are compared: what a padding step holds is never read."""
    result = CheckResult("pictures that come late")
    gen = torch.Generator().manual_seed(whole_number("seed", seed, 0, MAX_SEED))
    vision, steps = torch.rand(3, 12, 30, generator=gen), torch.tensor([12, 6, 9])
    real = (torch.arange(12)[None] < steps[:, None])[..., None]                 # (B, S, 1)
    result.note(f"input: vision {tuple(vision.shape)} (frames past steps are padding), steps {steps.tolist()}")

    def judged(out: Any, reference: torch.Tensor) -> Any:                     # padding steps: not judged
        same = isinstance(out, torch.Tensor) and out.shape == reference.shape and out.dtype == reference.dtype
        return torch.where(real, out, reference) if same else out
    for k in (0, 2, -3, 40):
        given: dict[str, Any] = {"vision": vision.clone(), "steps": steps.clone()}
        out = _call(result, f"your delayed(vision, {k}, steps)", student, given["vision"], k, given["steps"])
        if out is RAISED:
            return result
        if out is None:
            return result.fail("your delayed returned None; expected a tensor (B, S, 30)",
                               "a stub returns None: end with return the delayed frames")
        _unchanged(result, "your delayed", given, {"vision": vision, "steps": steps})
        expected = delayed_vision(vision, k, steps)
        if not _compare(result, f"k = {k}", judged(out, expected), expected):
            t = torch.arange(12)[None]
            _diagnose(result, [judged(out, expected)], [
                ("torch.roll wraps the last frames round to the start; step t < k must read the first frame",
                 [judged(torch.roll(vision, k, dims=1), expected)]),
                ("step t reads frame t − k (late), not t + k", [judged(delayed_vision(vision, -k, steps), expected)]),
                ("past each episode's length the frames are padding: clamp to its last real frame, steps[b] − 1",
                 [judged(vision.gather(1, (t - k).clamp(0, 11).expand(3, 12)[..., None].expand_as(vision)),
                         expected)]),
            ], DELAY_RULE)
        if not result:
            return result
    return result.ok("late, leading and held frames as the chapter's delay test reads them")


__all__ = ["check_nrmse", "check_tracking_target", "check_delayed", "delayed_vision"]
