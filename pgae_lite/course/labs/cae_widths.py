"""Lab: the CAE's channel widths (paper Sec. 3, "Visual Feature Extraction": the channel-separated CAE).

The action encoder reads 30 visual features per step, v_t = [E_R(x_t^R); E_G(x_t^G); E_B(x_t^B)] in R^30,
from three one-colour autoencoders trained on the reconstruction's binary cross-entropy,

    BCE(x, x̂) = −mean(x · log x̂ + (1 − x) · log(1 − x̂)),   x̂ = sigmoid(decoder(E(x))).

Each encoder's four convolutions have 8, 16, 32 and 64 channels (the authors' code; :mod:`pgae_lite.cae`).
The student writes one colour's autoencoder with half those widths, 4-8-16-32 (the decoder mirrors them:
16, 8, 4, 1), the package trains three of them as the CAE (``train_cae(..., autoencoder=)``) on the book's
recorded frames at the lab's budget, and the lab measures what the widths buy: the reconstruction's BCE on
frames of the test episodes, the parameters, and the training time.

The student's component is a class (or any function of no arguments) whose instances have
``encode(x)``: (B, 1, 120, 160) in [0, 1] -> (B, 10), ``logits(z)``: (B, 10) -> (B, 1, 120, 160), and
``forward(x)`` = sigmoid(logits(encode(x))), as :class:`~pgae_lite.cae.ChannelAutoencoder`.
"""
from __future__ import annotations

import time
from dataclasses import replace
from typing import Callable

import numpy as np
import torch
from torch import nn

from pgae_lite.cae import HEIGHT, WIDTH, CAEConfig, ChannelAutoencoder, ChannelSeparatedCAE, train_cae
from pgae_lite.config import Profile, get_profile
from pgae_lite.exercises.result import RAISED, CheckResult, _build, _call, _returned, _value_problem
from pgae_lite.model.pgae import count_parameters
from pgae_lite.sim.dataset import DatasetConfig, load_episode
from pgae_lite.util.checks import MAX_SEED, whole_number

TITLE = "The CAE's channel widths: 4-8-16-32 in place of 8-16-32-64"
STUDENT_NAME = "MyAutoencoder"                   # the student's component, in the lab's notebook
BOOK_WIDTHS = CAEConfig().conv                   # (8, 16, 32, 64): the authors'
WIDTHS = (4, 8, 16, 32)                          # what the lab asks for: half of each
FEATURES = CAEConfig().features                  # 10 per colour: v_t in R^30
# The encoder's feature maps (120x160 -> 60x80 -> 30x40 -> 15x20 -> 3x4) and the decoder's, back up.
ENCODER_SIZES = ((60, 80), (30, 40), (15, 20), (3, 4))
DECODER_SIZES = ((15, 20), (30, 40), (60, 80), (HEIGHT, WIDTH))
# Deviation from the book: the lab's budget. The book's CAE trains 1000 iterations of batch 16 (about 3 min
# on one core); a lab trains this many (a profile with fewer, e.g. smoke, keeps its own).
ITERATIONS = 400
TRAIN_VARIATIONS = 2       # frames of the first two variations of every training pattern (both views)

FIGURES = {"heldout_bce": "held-out reconstruction BCE",
           "parameters": "parameters of the CAE (thousands)",
           "train_seconds": "training time (s)"}


# ------------------------------------------------------------------ the book's component and the reference change
def book_autoencoder() -> nn.Module:
    """The book's one-colour autoencoder: channels 8-16-32-64."""
    return ChannelAutoencoder(CAEConfig())


class HalfWidths(ChannelAutoencoder):
    """The reference change: one colour's autoencoder with channels 4-8-16-32 (decoder 16-8-4-1)."""

    def __init__(self):
        super().__init__(CAEConfig(conv=WIDTHS))


BASELINE, REFERENCE = book_autoencoder, HalfWidths


# ------------------------------------------------------------------ mistakes the check must name
def _up(cin: int, cout: int, kernel: int, stride: int, pad: int, extra: int = 0) -> list[nn.Module]:
    return [nn.ConvTranspose2d(cin, cout, kernel, stride, pad, output_padding=extra, bias=False),
            nn.BatchNorm2d(cout), nn.ReLU()]


class _EncoderOrderDecoder(HalfWidths):
    """Wrong: the decoder's channels follow the encoder's order (4, 8, 16, 1), not its mirror (16, 8, 4, 1)."""

    def __init__(self):
        super().__init__()
        c1, c2, c3, c4 = WIDTHS
        self.deconv = nn.Sequential(*_up(c4, c1, 8, 5, 2, extra=1), *_up(c1, c2, 4, 2, 1), *_up(c2, c3, 4, 2, 1),
                                    nn.ConvTranspose2d(c3, 1, 4, 2, 1))


class _WideBottleneck(ChannelAutoencoder):
    """Wrong: 30 features per colour (v_t would be 90 numbers)."""

    def __init__(self):
        super().__init__(CAEConfig(conv=WIDTHS, features=3 * FEATURES))


class _LogitsAsPixels(HalfWidths):
    """Wrong: ``forward`` returns the decoder's logits, not pixels (no sigmoid)."""

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return self.logits(self.encode(x))


class _DetachedCode(HalfWidths):
    """Wrong: the code is detached, so the reconstruction's error never reaches the encoder."""

    def encode(self, x: torch.Tensor) -> torch.Tensor:
        return super().encode(x).detach()


WRONG = {
    "the book's widths": (book_autoencoder, "the lab asks for (4, 8, 16, 32)"),
    "decoder not mirrored": (_EncoderOrderDecoder, "mirror"),
    "30 features per colour": (_WideBottleneck, "10 features"),
    "forward returns logits": (_LogitsAsPixels, "outside [0, 1]"),
    "detached code": (_DetachedCode, "no gradient reaches"),
}


# ------------------------------------------------------------------ the check
def _traced(module: nn.Module, kind: type, fn: Callable, *args):
    """``fn(*args)`` and the (channels, height, width) of what each ``kind`` layer of ``module`` gave, in order."""
    seen: list[tuple[int, ...]] = []
    hooks = [m.register_forward_hook(lambda _m, _i, out: seen.append(tuple(out.shape[1:])))
             for m in module.modules() if type(m) is kind]
    try:
        return fn(*args), seen
    finally:
        for h in hooks:
            h.remove()


def _layers(result: CheckResult, seen: list[tuple[int, ...]], channels: tuple[int, ...], sizes: tuple,
            what: str, hint: str) -> bool:
    """Whether ``seen`` (from :func:`_traced`) has ``channels`` at ``sizes``; if not, a failure line."""
    got = tuple(s[0] for s in seen)
    if got == channels and tuple(s[1:] for s in seen) == sizes:
        result.ok(f"{what}: channels {got} at {' -> '.join(f'{h}x{w}' for h, w in sizes)}")
        return True
    maps = ", ".join(f"{c}x{h}x{w}" for c, h, w in seen) or "none"
    result.fail(f"{what} give {len(seen)} feature maps ({maps}); expected channels {channels} "
                f"at {', '.join(f'{h}x{w}' for h, w in sizes)}", hint)
    return False


def _structure(result: CheckResult, module: nn.Module, batch: int, gen: torch.Generator) -> bool:
    """One colour alone: the encoder's widths, the 10-d code, the decoder's mirrored widths."""
    missing = [m for m in ("encode", "logits", "forward") if not callable(getattr(module, m, None))]
    if missing:
        result.fail(f"your autoencoder lacks {', '.join(missing)}", "define encode(x) -> z, logits(z) -> the "
                    "image before the sigmoid, and forward(x) -> pixels, as ChannelAutoencoder does")
        return False
    x = torch.rand(batch, 1, HEIGHT, WIDTH, generator=gen)
    z, seen = _traced(module, nn.Conv2d, lambda: _call(result, "encode(x)", module.encode, x))
    if z is RAISED:
        return False
    ok = _layers(result, seen, WIDTHS, ENCODER_SIZES, "the encoder's convolutions",
                 f"the lab asks for {WIDTHS} channels (the book's: {BOOK_WIDTHS}), with the book's kernels, "
                 "strides and paddings")
    if not isinstance(z, torch.Tensor) or z.shape != (batch, FEATURES):
        what = f"shape {tuple(z.shape)}" if isinstance(z, torch.Tensor) else _returned(z)
        result.fail(f"encode(x) of {batch} images gave {what}; each colour's encoder gives {FEATURES} features, "
                    f"(B, {FEATURES}), so that v_t = [R; G; B] is in R^{3 * FEATURES}",
                    "the last fully connected layer has 10 outputs (CAEConfig.features)")
        return False
    result.ok(f"encode: (B, 1, {HEIGHT}, {WIDTH}) -> (B, {FEATURES})")
    out, seen = _traced(module, nn.ConvTranspose2d, lambda: _call(result, "logits(z)", module.logits, z))
    if out is RAISED:
        return False
    mirror = (*WIDTHS[-2::-1], 1)                                         # (16, 8, 4, 1)
    ok &= _layers(result, seen, mirror, DECODER_SIZES, "the decoder's transposed convolutions",
                  f"the decoder mirrors the encoder: {WIDTHS[-1]} -> {' -> '.join(map(str, mirror))}, the last "
                  "one without BatchNorm and ReLU (its output is logits)")
    if not isinstance(out, torch.Tensor) or out.shape != (batch, 1, HEIGHT, WIDTH):
        what = f"shape {tuple(out.shape)}" if isinstance(out, torch.Tensor) else _returned(out)
        result.fail(f"logits(z) gave {what}; expected ({batch}, 1, {HEIGHT}, {WIDTH})")
        return False
    return ok


def _behaviour(result: CheckResult, component: Callable, batch: int, gen: torch.Generator) -> None:
    """Three of them as the CAE: 30 features, pixels in [0, 1], the loss's gradient in every parameter."""
    cae = _call(result, "ChannelSeparatedCAE with your autoencoder",
                lambda: ChannelSeparatedCAE(CAEConfig(conv=WIDTHS), lambda _config: component()))
    if cae is RAISED:
        return
    images = torch.randint(0, 256, (batch, HEIGHT, WIDTH, 3), dtype=torch.uint8, generator=gen)
    v = _call(result, f"the CAE's encode on a ({batch}, {HEIGHT}, {WIDTH}, 3) batch", cae.encode, images)
    if isinstance(v, torch.Tensor) and v.shape == (batch, 3 * FEATURES) and not _value_problem(v, v.float()):
        result.ok(f"the CAE: ({batch}, {HEIGHT}, {WIDTH}, 3) frames -> v_t ({batch}, {3 * FEATURES})")
    elif v is not RAISED:
        result.fail(f"the CAE's features are {_returned(v)}; expected finite ({batch}, {3 * FEATURES})")
        return
    pixels = _call(result, "the CAE's forward", cae, images)
    if isinstance(pixels, torch.Tensor) and pixels.shape == (batch, 3, HEIGHT, WIDTH):
        low, high = pixels.min().item(), pixels.max().item()
        if 0 <= low and high <= 1:
            result.ok(f"reconstructions ({batch}, 3, {HEIGHT}, {WIDTH}), pixels in [0, 1]")
        else:
            result.fail(f"reconstructed pixels lie outside [0, 1] (from {low:.3g} to {high:.3g})",
                        "forward(x) returns pixels: torch.sigmoid(self.logits(self.encode(x)))")
    elif pixels is not RAISED:
        result.fail(f"the CAE's forward gave {_returned(pixels)}; expected ({batch}, 3, {HEIGHT}, {WIDTH})")
    loss = _call(result, "the CAE's loss", lambda: cae.loss(images)[0])
    if not isinstance(loss, torch.Tensor) or _call(result, "the backward pass", loss.backward) is RAISED:
        return
    dead = [n for n, p in cae.red.named_parameters() if p.grad is None or not torch.isfinite(p.grad).all()
            or not p.grad.any()]
    if dead:
        more = f" and {len(dead) - 3} more" if len(dead) > 3 else ""
        result.fail(f"no gradient reaches {', '.join(dead[:3])}{more} (parameters of one colour's autoencoder)",
                    "every layer must be used on the way from x to the logits, and nothing detached")
    else:
        result.ok(f"BCE {loss.item():.3f}; its gradient reaches every parameter")


@torch.random.fork_rng(devices=[])
def check(component: Callable[[], nn.Module], seed: int = 0, batch: int = 3) -> CheckResult:
    """Judge one colour's autoencoder with the lab's widths by its structure and its behaviour in the CAE.

    ``component()`` builds it. Structure: the encoder's four convolutions have channels 4-8-16-32 and
    give 60x80 -> 30x40 -> 15x20 -> 3x4 maps, ``encode`` gives 10 features, and the decoder's transposed
    convolutions mirror the encoder back to one 120x160 channel. Behaviour: three of them as
    :class:`~pgae_lite.cae.ChannelSeparatedCAE` turn a (``batch``, 120, 160, 3) batch into 30 features and into
    pixels in [0, 1], and the BCE's gradient reaches every parameter.
    """
    seed, batch = whole_number("seed", seed, 0, MAX_SEED), whole_number("batch", batch, 2, 64)
    result, gen = CheckResult(f"one colour's autoencoder, channels {'-'.join(map(str, WIDTHS))}"), \
        torch.Generator().manual_seed(seed)
    torch.manual_seed(seed)                                  # the student's initialisation: the same every run
    module = _build(result, component, name=getattr(component, "__name__", "component"))
    if module is None or not _structure(result, module, batch, gen):
        return result
    _behaviour(result, component, batch, gen)
    if result:
        result.note(f"parameters of one colour's autoencoder: yours {count_parameters(module):,}, "
                    f"the book's {count_parameters(book_autoencoder()):,}")
    return result


# ------------------------------------------------------------------ the student's run
def lab_frames(data: DatasetConfig, stride: int) -> tuple[np.ndarray, np.ndarray]:
    """The lab's frames, uint8 (N, 120, 160, 3), both views, every ``stride``-th step: for training, the first
    two variations of every training pattern; held out, the first variation of every test pattern."""
    world = data.the_world

    def frames(test: bool, variations: int) -> np.ndarray:
        chosen = [(p, v) for p in data.pattern_list() for v in range(min(variations, data.variations))
                  if world.pattern(p).is_test == test]
        return np.concatenate([view[::stride] for p, v in chosen for ep in [load_episode(data, p, v)]
                               for view in (ep.images, ep.images_opposite)])
    # Deviation from the book: a third of the CAE's training frames (the book reads all six variations),
    # read in a third of the time; the lab trains on fewer frames than that anyway.
    return frames(False, TRAIN_VARIATIONS), frames(True, 1)


@torch.no_grad()
def heldout_bce(model: ChannelSeparatedCAE, frames: np.ndarray, batch: int = 128) -> float:
    """The mean BCE of ``model``'s reconstructions of ``frames`` (eval mode: BatchNorm's running statistics)."""
    model.eval()
    total = sum(model.loss(frames[i:i + batch])[0].item() * len(frames[i:i + batch])
                for i in range(0, len(frames), batch))
    return total / len(frames)


def run(component: Callable[[], nn.Module], seed: int = 0, profile: Profile | str | None = None,
        progress: bool = False) -> dict[str, float]:
    """Train the CAE of three ``component()`` autoencoders at the lab's budget; its figures (see FIGURES).

    The profile's CAE recipe (batch, rate) with ``min(its iterations, ITERATIONS)`` iterations and ``seed``,
    on :func:`lab_frames` of the profile's recordings (the cache's: recorded if missing).
    """
    prof = profile if isinstance(profile, Profile) else get_profile(profile)
    seed = whole_number("seed", seed, 0, MAX_SEED)
    config = replace(prof.cae, name="lab-cae_widths", iterations=min(prof.cae.iterations, ITERATIONS), seed=seed)
    train, held_out = lab_frames(prof.data, prof.cae.frame_stride)
    start = time.perf_counter()
    model, _ = train_cae(train, config, progress=progress, autoencoder=lambda _config: component())
    seconds = time.perf_counter() - start
    return {"heldout_bce": heldout_bce(model, held_out), "parameters": count_parameters(model) / 1000,
            "train_seconds": seconds}


__all__ = ["BASELINE", "FIGURES", "HalfWidths", "REFERENCE", "STUDENT_NAME", "TITLE", "WIDTHS", "WRONG", "check",
           "heldout_bce", "lab_frames", "run"]
