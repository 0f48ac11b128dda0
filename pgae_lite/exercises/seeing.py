"""Checks of the seeing chapter's exercises: the channel split, the CAE's loss, the 30 visual features.

Paper, Sec. 3 ("Action Encoder"): each frame is compressed by a channel-separated
convolutional autoencoder, one autoencoder per colour channel, trained with the binary
cross-entropy of its reconstruction, and the three 10-d codes are concatenated into
v_t = [E_R(x^R); E_G(x^G); E_B(x^B)] (chapter 03, :mod:`pgae_lite.cae`). Each check runs a
student's function next to the package's on seeded random images and a freshly built
:class:`~pgae_lite.cae.ChannelSeparatedCAE`, and names a known mistake when one reproduces the
student's outputs.
"""
from __future__ import annotations

import copy
from typing import Any, Callable

import numpy as np
import torch
from torch import nn

from pgae_lite.cae import HEIGHT, WIDTH, CAEConfig, ChannelSeparatedCAE
from pgae_lite.exercises.result import RAISED, CheckResult, _call, _compare, _diagnose, _returned
from pgae_lite.util.checks import MAX_SEED, whole_number

SPLIT_RULE = "x = images / 255 as (B, 3, 120, 160) (permute the axes), then x[:, i:i+1] for i = R, G, B"
LOSS_EQUATION = ("BCE_c = −mean(x_c · log x̂_c + (1 − x_c) · log(1 − x̂_c)), x̂_c = sigmoid(logits of channel c's own "
                 "autoencoder); the loss is the mean of BCE_R, BCE_G, BCE_B")
FEATURES_EQUATION = "v_t = [E_R(x^R); E_G(x^G); E_B(x^B)], 10 + 10 + 10 = 30 features, red first"
BATCH = 3


def _images(seed: int) -> np.ndarray:
    """``BATCH`` seeded random frames as the simulator gives them: uint8 (B, 120, 160, 3)."""
    rng = np.random.default_rng(whole_number("seed", seed, 0, MAX_SEED))
    return rng.integers(0, 256, (BATCH, HEIGHT, WIDTH, 3), dtype=np.uint8)


def _model(seed: int) -> ChannelSeparatedCAE:
    """A seeded, untrained CAE in eval mode (BatchNorm uses its running statistics: no batch dependence)."""
    torch.manual_seed(seed)
    return ChannelSeparatedCAE(CAEConfig()).eval()


class _Blocked:
    """A method the student is asked to write, not to call: calling it raises with a hint."""

    def __init__(self, name: str, hint: str):
        self.name, self.hint = name, hint

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        raise RuntimeError(f"model.{self.name} is what you are asked to write: {self.hint}")


def _given(model: ChannelSeparatedCAE, blocked: str, hint: str) -> ChannelSeparatedCAE:
    """The student's copy of ``model``, with the method ``blocked`` replaced by one that says so."""
    given = copy.deepcopy(model)
    setattr(given, blocked, _Blocked(blocked, hint))
    return given


def _ask(title: str, student: Callable, seed: int, method: str, hint: str) -> tuple:
    """Run ``student(model, images)`` on a seeded untrained CAE whose ``method`` is blocked (it is what the
    student writes): ``(result, model, images, what model.method gives, what the student's gave)``."""
    result = CheckResult(title)
    images, model = _images(seed), _model(seed)
    result.note(f"input: an untrained ChannelSeparatedCAE in eval mode and uint8 frames {images.shape}")
    expected = getattr(model, method)(images)
    out = _call(result, f"your {title.split()[-1]}", student, _given(model, method, hint), images.copy())
    return result, model, images, expected, out


def _tensors(out: Any, n: int) -> list | None:
    """``out`` as a list when it is a list or tuple of ``n`` items, else None."""
    return list(out) if isinstance(out, (list, tuple)) and len(out) == n else None


# ------------------------------------------------------------------ the channel split
@torch.random.fork_rng(devices=[])
def check_channel_split(student: Callable, seed: int = 0) -> CheckResult:
    """``student(images) -> [x_R, x_G, x_B]``: uint8 frames (B, 120, 160, 3) to three float tensors
    (B, 1, 120, 160) in [0, 1], one per colour channel, as the CAE's autoencoders read them.

    The reference is :meth:`ChannelSeparatedCAE._split <pgae_lite.cae.ChannelSeparatedCAE>`.
    """
    result = CheckResult("channel split")
    images = _images(seed)
    result.note(f"input: uint8 frames {images.shape}, as the simulator renders them (height, width, RGB)")
    expected = _model(seed)._split(images)                                  # 3 x (B, 1, 120, 160)
    out = _call(result, "your split", student, images.copy())
    if out is RAISED:
        return result
    got = _tensors(out, 3)
    if got is None:
        return result.fail(f"your split returned {_returned(out)}; expected a list of 3 tensors (B, 1, 120, 160), "
                           "one per colour: red, green, blue",
                           "a stub returns None: end with return [x_r, x_g, x_b]" if out is None else None)
    if any(isinstance(t, torch.Tensor) and t.shape == (BATCH, HEIGHT, WIDTH) for t in got):
        return result.fail(f"a channel has shape {(BATCH, HEIGHT, WIDTH)}: the channel axis is gone",
                           "keep it, as each autoencoder reads (B, 1, 120, 160): x[:, i:i+1], not x[:, i]")
    if all([_compare(result, f"x_{c}", g, e) for c, g, e in zip("RGB", got, expected)]):
        return result.ok("each autoencoder gets its own colour channel, scaled to [0, 1]")
    x = torch.from_numpy(images).float()                                    # (B, 120, 160, 3), 0..255
    scrambled = x.reshape(BATCH, 3, HEIGHT, WIDTH) / 255                    # a reshape, not a permute
    _diagnose(result, got, [
        ("the values are right but not float32 (numpy's / 255 gives float64): torch.from_numpy(images).float() / 255",
         expected),
        ("the pixels are still 0..255: divide by 255, so that they lie in [0, 1] as the BCE needs",
         [c * 255 for c in expected]),
        ("the channels come in the order B, G, R (OpenCV's); the frames are R, G, B", expected[::-1]),
        ("you reshaped (B, 120, 160, 3) to (B, 3, 120, 160): that scrambles the pixels; "
         "move the axis with permute(0, 3, 1, 2)", [scrambled[:, i:i + 1] for i in range(3)]),
    ], SPLIT_RULE)
    return result


# ------------------------------------------------------------------ the CAE's loss
def _loss_variant(model: ChannelSeparatedCAE, images: np.ndarray, bce: Callable | None = None,
                  scale: float = 1.0, one_autoencoder: bool = False, total: str = "mean") -> tuple:
    """The CAE's loss (mean, per channel (3,)), with switches that reproduce common mistakes."""
    bce = bce or nn.functional.binary_cross_entropy_with_logits
    channels = model._split(images)                                          # 3 x (B, 1, 120, 160) in [0, 1]
    encoders = [model.red] * 3 if one_autoencoder else model.channels
    per = torch.stack([bce(ae.logits(ae.encode(x)), x * scale) for ae, x in zip(encoders, channels)])  # (3,)
    return (per.sum() if total == "sum" else per.mean()), per


@torch.random.fork_rng(devices=[])
@torch.no_grad()
def check_cae_loss(student: Callable, seed: int = 0) -> CheckResult:
    """``student(model, images) -> (loss, per_channel)``: the CAE's training loss, the mean of the three
    channels' binary cross-entropies, and those three (a tensor (3,), R, G, B), against
    :meth:`ChannelSeparatedCAE.loss <pgae_lite.cae.ChannelSeparatedCAE.loss>` on seeded frames.

    ``model`` is a :class:`~pgae_lite.cae.ChannelSeparatedCAE`: use ``model.red``, ``model.green``,
    ``model.blue`` (each has ``encode`` and ``logits``), not ``model.loss``.
    """
    result, model, images, expected, out = _ask(
        "CAE loss", student, seed, "loss", "compute each channel's BCE with model.red, model.green and model.blue")
    if out is RAISED:
        return result
    got = _tensors(out, 2)
    if got is None:
        return result.fail(f"your loss returned {_returned(out)}; expected the pair (loss, per_channel): "
                           "a 0-d tensor and a tensor (3,)",
                           "a stub returns None: end with return loss, per_channel" if out is None else None)
    parts = _tensors(got[1], 3)
    if parts is not None and all(isinstance(p, torch.Tensor) and p.dim() == 0 for p in parts):
        got[1] = torch.stack(parts)                                          # three 0-d tensors: accepted
    if all([_compare(result, "loss", got[0], expected[0]), _compare(result, "per_channel", got[1], expected[1])]):
        return result.ok("each channel's BCE from its own autoencoder, and their mean")
    _diagnose(result, got, [
        ("that is the mean squared error; the CAE's loss is the binary cross-entropy",
         _loss_variant(model, images, lambda logits, x: nn.functional.mse_loss(torch.sigmoid(logits), x))),
        ("you summed over the pixels; the BCE is the mean over the batch and the pixels",
         _loss_variant(model, images, lambda logits, x: nn.functional.binary_cross_entropy_with_logits(
             logits, x, reduction="sum"))),
        ("the loss is the MEAN of the three channels' BCE, not their sum",
         _loss_variant(model, images, total="sum")),
        ("every channel went through model.red: each colour has its own autoencoder (red, green, blue)",
         _loss_variant(model, images, one_autoencoder=True)),
        ("the arguments are swapped: BCE(input = the reconstruction x̂, target = the image x)",
         _loss_variant(model, images, lambda logits, x: nn.functional.binary_cross_entropy(
             x, torch.sigmoid(logits)))),
        ("the sigmoid is applied twice: binary_cross_entropy_with_logits takes the logits, "
         "binary_cross_entropy the probabilities sigmoid(logits)",
         _loss_variant(model, images, lambda logits, x: nn.functional.binary_cross_entropy_with_logits(
             torch.sigmoid(logits), x))),
        ("the targets are 0..255: divide the pixels by 255",
         _loss_variant(model, images, lambda logits, x: nn.functional.binary_cross_entropy_with_logits(
             logits, x), scale=255.0)),
    ], LOSS_EQUATION)
    return result


# ------------------------------------------------------------------ the 30 visual features
@torch.random.fork_rng(devices=[])
@torch.no_grad()
def check_visual_features(student: Callable, seed: int = 0) -> CheckResult:
    """``student(model, images) -> v`` (B, 30): the visual features [R10, G10, B10] of uint8 frames
    (B, 120, 160, 3), each block from its own channel's encoder, against
    :meth:`ChannelSeparatedCAE.encode <pgae_lite.cae.ChannelSeparatedCAE.encode>`.

    Use ``model.red.encode``, ``model.green.encode``, ``model.blue.encode`` (each takes (B, 1, 120, 160)
    in [0, 1]), not ``model.encode``.
    """
    result, model, images, expected, out = _ask(                             # expected: (B, 30)
        "visual features", student, seed, "encode",
        "encode each channel with model.red, model.green, model.blue and join them")
    if out is RAISED:
        return result
    if isinstance(out, torch.Tensor) and out.shape == (BATCH, 3, model.config.features):
        return result.fail(f"your features have shape {tuple(out.shape)}: stacked, not concatenated",
                           "torch.cat([v_r, v_g, v_b], dim=1) gives (B, 30)")
    if isinstance(out, np.ndarray):
        return result.fail("your features are a numpy array; expected a torch tensor (B, 30)",
                           "the encoders give tensors: join them with torch.cat")
    if _compare(result, "v", out, expected):
        return result.ok("[E_R(x^R); E_G(x^G); E_B(x^B)]: the red block first, each from its own encoder")
    blocks = expected.split(model.config.features, dim=1)                    # 3 x (B, 10)
    x = torch.from_numpy(images).permute(0, 3, 1, 2).float()                # (B, 3, 120, 160), 0..255
    _diagnose(result, [out], [
        ("the blocks come in the order B, G, R; v_t is [R10, G10, B10], red first", [torch.cat(blocks[::-1], 1)]),
        ("you interleaved the channels (r0, g0, b0, r1, ...): concatenate the blocks with torch.cat(..., dim=1)",
         [torch.stack(blocks, 2).flatten(1)]),
        ("every channel went through model.red: each colour has its own encoder",
         [torch.cat([model.red.encode(x[:, i:i + 1] / 255) for i in range(3)], 1)]),
        ("the encoders read pixels in [0, 1]: divide the uint8 values by 255",
         [torch.cat([ae.encode(x[:, i:i + 1]) for i, ae in enumerate(model.channels)], 1)]),
    ], FEATURES_EQUATION)
    return result


__all__ = ["check_channel_split", "check_cae_loss", "check_visual_features"]
