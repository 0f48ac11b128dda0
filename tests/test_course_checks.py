"""The checks the course's problem sets grade with (pgae_lite/exercises/seeing.py, acting.py): the reference
passes, each named mistake gets its diagnosis; and the problem sets' master notebooks are well formed."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import torch
from torch.nn import functional as F

from pgae_lite.exercises import (
    CheckResult,
    check_cae_loss,
    check_channel_split,
    check_delayed,
    check_nrmse,
    check_tracking_target,
    check_visual_features,
)
from pgae_lite.exercises.acting import delayed_vision

PROBLEM_SETS = Path(__file__).resolve().parent.parent / "course" / "problem_sets"


def failed_with(result: CheckResult, *phrases: str) -> bool:
    """The check failed, and its report contains every phrase."""
    text = str(result)
    return not result and all(p in text for p in phrases)


# ------------------------------------------------------------------ seeing: the channel split
def split(images, scale=255.0, order=(0, 1, 2)):
    """The reference solution: (B, 120, 160, 3) uint8 -> 3 x (B, 1, 120, 160) float32 in [0, 1]."""
    x = torch.from_numpy(images).permute(0, 3, 1, 2).float() / scale
    return [x[:, i:i + 1] for i in order]


def reshaped(images):
    x = torch.from_numpy(images).float().reshape(len(images), 3, 120, 160) / 255
    return [x[:, i:i + 1] for i in range(3)]


@pytest.mark.parametrize("seed", [0, 1])
def test_channel_split_passes_the_reference(seed):
    assert check_channel_split(split, seed=seed)


@pytest.mark.parametrize("student, phrases", [
    (lambda im: split(im, scale=1.0), ["still 0..255"]),
    (lambda im: split(im, order=(2, 1, 0)), ["B, G, R"]),
    (reshaped, ["permute(0, 3, 1, 2)"]),
    (lambda im: [t[:, 0] for t in split(im)], ["channel axis is gone", "x[:, i:i+1]"]),
    (lambda im: [t.double() for t in split(im)], ["not float32"]),
    (lambda im: split(im)[:2], ["list of 3 tensors"]),
    (lambda im: None, ["stub returns None"]),
    (lambda im: 1 / 0, ["raised ZeroDivisionError"]),
])
def test_channel_split_names_the_mistake(student, phrases):
    result = check_channel_split(student)
    assert failed_with(result, *phrases), result


# ------------------------------------------------------------------ seeing: the CAE's loss
def cae_loss(model, images, bce=F.binary_cross_entropy_with_logits, encoders=None, total="mean", scale=1.0):
    """The reference solution, with switches for the mistakes."""
    encoders = encoders or (model.red, model.green, model.blue)
    per = torch.stack([bce(ae.logits(ae.encode(x)), x * scale) for ae, x in zip(encoders, split(images))])
    return (per.mean() if total == "mean" else per.sum()), per


def by_hand(model, images):
    """BCE written out from the reconstruction x̂ = ae(x): the same numbers."""
    per = []
    for ae, x in zip((model.red, model.green, model.blue), split(images)):
        x_hat = ae(x)
        per.append(-(x * torch.log(x_hat) + (1 - x) * torch.log(1 - x_hat)).mean())
    return torch.stack(per).mean(), per           # a list of three 0-d tensors is accepted


@pytest.mark.parametrize("student", [cae_loss, by_hand])
def test_cae_loss_passes_the_reference(student):
    assert check_cae_loss(student)
    assert check_cae_loss(student, seed=2)


@pytest.mark.parametrize("student, phrases", [
    (lambda m, im: cae_loss(m, im, lambda lg, x: F.mse_loss(torch.sigmoid(lg), x)), ["mean squared error"]),
    (lambda m, im: cae_loss(m, im, lambda lg, x: F.binary_cross_entropy_with_logits(lg, x, reduction="sum")),
     ["summed over the pixels"]),
    (lambda m, im: cae_loss(m, im, total="sum"), ["MEAN of the three channels"]),
    (lambda m, im: cae_loss(m, im, encoders=(m.red,) * 3), ["own autoencoder"]),
    (lambda m, im: cae_loss(m, im, lambda lg, x: F.binary_cross_entropy(x, torch.sigmoid(lg))), ["swapped"]),
    (lambda m, im: cae_loss(m, im, lambda lg, x: F.binary_cross_entropy_with_logits(torch.sigmoid(lg), x)),
     ["sigmoid is applied twice"]),
    (lambda m, im: cae_loss(m, im, scale=255.0), ["divide the pixels by 255"]),
    (lambda m, im: m.loss(im), ["model.loss is what you are asked to write"]),
    (lambda m, im: cae_loss(m, im)[0], ["pair (loss, per_channel)"]),
    (lambda m, im: None, ["stub returns None"]),
])
def test_cae_loss_names_the_mistake(student, phrases):
    result = check_cae_loss(student)
    assert failed_with(result, *phrases), result


# ------------------------------------------------------------------ seeing: the 30 visual features
def features(model, images, encoders=None, scale=255.0, join="cat", order=(0, 1, 2)):
    encoders = encoders or (model.red, model.green, model.blue)
    blocks = [ae.encode(x) for ae, x in zip(encoders, split(images, scale))]
    blocks = [blocks[i] for i in order]
    return torch.cat(blocks, 1) if join == "cat" else torch.stack(blocks, 2 if join == "interleave" else 1)


def test_visual_features_pass_the_reference():
    assert check_visual_features(features)
    assert check_visual_features(features, seed=3)


@pytest.mark.parametrize("student, phrases", [
    (lambda m, im: features(m, im, order=(2, 1, 0)), ["order B, G, R"]),
    (lambda m, im: features(m, im, join="interleave").flatten(1), ["interleaved"]),
    (lambda m, im: features(m, im, join="stack"), ["stacked, not concatenated"]),
    (lambda m, im: features(m, im, encoders=(m.red,) * 3), ["own encoder"]),
    (lambda m, im: features(m, im, scale=1.0), ["divide the uint8 values by 255"]),
    (lambda m, im: features(m, im).numpy(), ["numpy array"]),
    (lambda m, im: m.encode(im), ["model.encode is what you are asked to write"]),
])
def test_visual_features_name_the_mistake(student, phrases):
    result = check_visual_features(student)
    assert failed_with(result, *phrases), result


# ------------------------------------------------------------------ acting: Table 1's nRMSE
def nrmse(joints, target, lengths, joint_range, first=1, padded=False):
    """The reference solution: pooled over every episode's steps first..length-1."""
    t = np.arange(joints.shape[1])[None]
    steps = (t >= first) & ((t < lengths[:, None]) | padded)
    return 100 * np.sqrt(((joints - target) ** 2)[steps].mean()) / joint_range


def per_episode(joints, target, lengths, joint_range):
    return np.mean([100 * np.sqrt(((joints[i, 1:n] - target[i, 1:n]) ** 2).mean()) / joint_range
                    for i, n in enumerate(lengths)])


def own_range(joints, target, lengths, joint_range):
    valid = np.arange(joints.shape[1])[None] < lengths[:, None]
    return nrmse(joints, target, lengths, float(np.ptp(target[valid])))


@pytest.mark.parametrize("student", [nrmse, lambda *a: torch.tensor(nrmse(*a)), lambda *a: np.float32(nrmse(*a))])
def test_nrmse_passes_the_reference(student):
    assert check_nrmse(student)
    assert check_nrmse(student, seed=5)


@pytest.mark.parametrize("student, phrases", [
    (lambda *a: nrmse(*a, padded=True), ["padded convention"]),
    (lambda *a: nrmse(*a, first=0), ["step 0 is the given start pose"]),
    (lambda *a: nrmse(*a) / 100, ["multiply by 100"]),
    (lambda *a: (nrmse(*a) / 100) ** 2 * a[3] * 100, ["square root"]),
    (per_episode, ["averaged the episodes' own nRMSEs"]),
    (own_range, ["joint_range you are given"]),
    (lambda *a: np.ones(3), ["shape (3,)"]),
    (lambda *a: None, ["stub returns None"]),
    (lambda j, *a: j.fill(0), ["stub returns None"]),
])
def test_nrmse_names_the_mistake(student, phrases):
    result = check_nrmse(student)
    assert failed_with(result, *phrases), result


def test_nrmse_notices_changed_inputs():
    def changing(joints, target, lengths, joint_range):
        value = nrmse(joints, target, lengths, joint_range)
        joints[:] = 0
        return value
    assert failed_with(check_nrmse(changing), "changed joints in place")


# ------------------------------------------------------------------ acting: the tracking target
def tracking(q, desired, gain, substeps, alpha=None):
    alpha = alpha if alpha is not None else 1 - (1 - gain) ** substeps
    return q + (desired - q) / alpha


def test_tracking_target_passes_and_reaches_the_joints_in_the_simulator():
    result = check_tracking_target(tracking)
    assert result and "in the simulator the arm ends" in str(result)
    assert check_tracking_target(lambda *a: torch.from_numpy(tracking(*a)), seed=4)


@pytest.mark.parametrize("student, phrases", [
    (lambda q, d, g, s: d, ["no tracking"]),
    (lambda q, d, g, s: tracking(q, d, g, s, alpha=g), ["not the gain of one substep"]),
    (lambda q, d, g, s: tracking(q, d, g, s, alpha=g * s), ["not substeps × gain"]),
    (lambda q, d, g, s: tracking(q, d, g, s, alpha=(1 - g) ** s), ["share left OPEN"]),
    (lambda q, d, g, s: q + (d - q) * (1 - (1 - g) ** s), ["do not multiply"]),
    (lambda q, d, g, s: d + (d - q) / (1 - (1 - g) ** s), ["MEASURED joints q"]),
    (lambda q, d, g, s: None, ["stub returns None"]),
    (lambda q, d, g, s: "u", ["expected 5 numbers"]),
])
def test_tracking_target_names_the_mistake(student, phrases):
    result = check_tracking_target(student)
    assert failed_with(result, *phrases), result


# ------------------------------------------------------------------ acting: pictures that come late
def late_by_hand(vision, k, steps):
    """The reference written as loops."""
    out = torch.empty_like(vision)
    for b in range(len(vision)):
        for t in range(vision.shape[1]):
            out[b, t] = vision[b, min(max(t - k, 0), int(steps[b]) - 1)]
    return out


def no_end_clamp(vision, k, steps):
    index = (torch.arange(vision.shape[1])[None] - k).clamp(0, vision.shape[1] - 1).expand(len(vision), -1)
    return vision.gather(1, index[..., None].expand_as(vision))


@pytest.mark.parametrize("student", [delayed_vision, late_by_hand])
def test_delayed_passes_the_reference(student):
    assert check_delayed(student)
    assert check_delayed(student, seed=7)


@pytest.mark.parametrize("student, phrases", [
    (lambda v, k, s: torch.roll(v, k, dims=1), ["torch.roll wraps"]),
    (lambda v, k, s: delayed_vision(v, -k, s), ["not t + k"]),
    (no_end_clamp, ["clamp to its last real frame"]),
    (lambda v, k, s: v.copy_(delayed_vision(v, k, s)), ["changed vision in place"]),
    (lambda v, k, s: v, ["k = 2 differs"]),
    (lambda v, k, s: None, ["stub returns None"]),
])
def test_delayed_names_the_mistake(student, phrases):
    result = check_delayed(student)
    assert failed_with(result, *phrases), result


def test_checks_refuse_a_bad_seed_with_a_clear_error():
    for check in (check_channel_split, check_nrmse, check_delayed):
        with pytest.raises(Exception, match="seed"):
            check(lambda *a: None, seed=-1)


# ------------------------------------------------------------------ the problem sets' masters
def cells(path: Path) -> list[dict]:
    return json.loads(path.read_text(encoding="utf-8"))["cells"]


def source(cell: dict) -> str:
    return "".join(cell["source"])


MASTERS = sorted(PROBLEM_SETS.glob("ps*.ipynb"))


def test_six_problem_sets():
    assert [p.stem.split("_")[0] for p in MASTERS] == [f"ps{n}" for n in range(1, 7)]


@pytest.mark.parametrize("path", MASTERS, ids=lambda p: p.stem)
def test_master_is_an_otter_assignment_without_outputs(path):
    notebook = json.loads(path.read_text(encoding="utf-8"))
    assert notebook["metadata"]["kernelspec"] == {"display_name": "Python 3", "language": "python",
                                                  "name": "python3"}
    assert all(not c.get("outputs") and not c.get("execution_count") for c in notebook["cells"]
               if c["cell_type"] == "code")
    first, intro = notebook["cells"][0], notebook["cells"][1]
    assert first["cell_type"] == "raw" and source(first).startswith("# ASSIGNMENT CONFIG")
    assert f"name: {path.stem}" in source(first)
    assert intro["cell_type"] == "markdown" and 'grader.check("q1")' in source(intro)
    questions = [source(c) for c in notebook["cells"]
                 if c["cell_type"] == "raw" and source(c).startswith("# BEGIN QUESTION")]
    assert 3 <= len(questions) <= 4
    assert any("manual: true" in q for q in questions), "every problem set has an open, hand-graded question"
    graded = [q for q in questions if "manual: true" not in q]
    tests = [source(c) for c in notebook["cells"] if c["cell_type"] == "code" and "hidden: true" in source(c)]
    assert len(tests) >= len(graded), "hidden tests for every graded question"
