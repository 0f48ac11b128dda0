"""Seeing: a frame's colour channels, reconstructions, the CAE's training curves, visual features.

Paper, Sec. 3 ("Action Encoder": the channel-separated convolutional
autoencoder and the 30 visual features it extracts per frame). Helpers of the CAE chapter (03), also
meant for later ones: a frame split into its colour channels, reconstructions
next to originals, the CAE's training curves, and the 30 visual features next
to the frames they come from (and over time, for the appendix's authors' data).
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence

import matplotlib.pyplot as plt
import numpy as np
import torch
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from pgae_lite.viz._common import JOINT_NAMES, _numpy

#: One colour per image channel (R, G, B), the same in every figure of the book.
CHANNEL_COLOURS: tuple[str, ...] = ("tab:red", "tab:green", "tab:blue")
_CHANNELS = ("red", "green", "blue")


def _feature_edges(ax: plt.Axes, features: int, horizontal: bool) -> None:
    """White lines between the R, G and B blocks of a feature axis (``features`` = 3 x per channel)."""
    for edge in (features / 3 - 0.5, 2 * features / 3 - 0.5):
        (ax.axhline if horizontal else ax.axvline)(edge, color="white", lw=1.5)


def plot_channels(frame: np.ndarray, title: str = "") -> Figure:
    """One frame (H, W, 3) uint8 and its red, green and blue channels, each as a grey image (0 black, 255 white)."""
    frame = _numpy(frame)
    fig, axes = plt.subplots(1, 4, figsize=(11, 2.5))
    axes[0].imshow(frame)
    axes[0].set_title("the frame (RGB)", fontsize=9)
    for k, ax in enumerate(axes[1:]):
        ax.imshow(frame[..., k], cmap="gray", vmin=0, vmax=255)
        ax.set_title(f"{_CHANNELS[k]} channel", fontsize=9, color=CHANNEL_COLOURS[k])
    for ax in axes:
        ax.set(xticks=[], yticks=[])
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_reconstructions(rows: Mapping[str, tuple[np.ndarray, np.ndarray]], size: float = 1.9) -> Figure:
    """Originals next to their reconstructions by a channel-separated CAE, one row per entry of ``rows``.

    ``rows`` maps a label to ``(original, reconstruction)``, both (H, W, 3)
    uint8 (e.g. from :func:`pgae_lite.cae.reconstruct`). Columns: the
    original; the reconstruction of each channel by its own autoencoder (grey),
    titled with its mean absolute error in grey levels (of 255); the three
    reconstructed channels recombined into one colour image.
    """
    rows = {label: (_numpy(a), _numpy(b)) for label, (a, b) in rows.items()}
    if not rows:
        raise ValueError("rows is empty: pass at least one label -> (original, reconstruction)")
    height, width = next(iter(rows.values()))[0].shape[:2]
    fig, axes = plt.subplots(len(rows), 5, squeeze=False,
                             figsize=(5 * size, len(rows) * (size * height / width + 0.35)))
    for r, (label, (original, rebuilt)) in enumerate(rows.items()):
        axes[r, 0].imshow(original)
        axes[r, 0].set_ylabel(label, fontsize=9)
        for k in range(3):
            error = np.abs(original[..., k].astype(float) - rebuilt[..., k]).mean()
            axes[r, k + 1].imshow(rebuilt[..., k], cmap="gray", vmin=0, vmax=255)
            axes[r, k + 1].set_title(f"error {error:.1f}", fontsize=8, color=CHANNEL_COLOURS[k])
        axes[r, 4].imshow(rebuilt)
    for c, name in enumerate(("original", "red, rebuilt", "green, rebuilt", "blue, rebuilt", "recombined")):
        axes[0, c].set_title(name if c in (0, 4) else f"{name}\n{axes[0, c].get_title()}", fontsize=9)
    for ax in axes.flat:
        ax.set(xticks=[], yticks=[])
    fig.tight_layout()
    return fig


def plot_cae_history(history: Sequence[Mapping], smooth: int = 25, floor: Sequence[float] | None = None,
                     levels: Mapping[str, Sequence[float]] | None = None) -> Figure:
    """CAE training curves from ``train_cae``'s history: the BCE of each channel per iteration, one panel each.

    Thin line: every iteration (one batch each); thick line: the mean of the
    last ``smooth`` iterations. ``levels`` maps a label to one value per
    channel (R, G, B), drawn as horizontal reference lines (e.g. the BCE of
    rebuilding every image as the mean image).

    ``floor`` (one value per channel) is the lowest BCE possible on the
    images: for pixel values between 0 and 1 even a perfect reconstruction
    scores their mean binary entropy, not 0. With it, the panels show the BCE
    *above* the floor on a log scale, where the late, small gains are visible
    (a batch below an estimated floor is then not drawn).
    """
    if not history:
        raise ValueError("history is empty: nothing to plot")
    iterations = np.array([r["iteration"] for r in history])
    smooth = max(1, min(smooth, len(history) // 4))
    base = np.zeros(3) if floor is None else np.asarray(floor, dtype=float)
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.2))
    for k, (ax, name) in enumerate(zip(axes, _CHANNELS)):
        loss = np.array([r[name] for r in history]) - base[k]
        total = np.concatenate([[0.0], np.cumsum(loss)])
        start = np.maximum(np.arange(len(loss)) + 1 - smooth, 0)           # trailing window, shorter at first
        ax.plot(iterations, loss, color=CHANNEL_COLOURS[k], lw=0.6, alpha=0.35)
        ax.plot(iterations, (total[1:] - total[start]) / (np.arange(len(loss)) + 1 - start),
                color=CHANNEL_COLOURS[k], lw=2, label=f"training (mean of {smooth})")
        for (label, values), style in zip((levels or {}).items(), (":", "--", "-.")):
            ax.axhline(values[k] - base[k], color="black", lw=1, ls=style, label=label)
        ax.set(xlabel="iteration", title=f"{name} channel", yscale="linear" if floor is None else "log")
        ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    axes[0].set_ylabel("BCE" if floor is None else "BCE above the floor")
    axes[-1].legend(fontsize="small", loc="upper right")
    fig.tight_layout()
    return fig


def plot_features_over_time(frames: np.ndarray, features: np.ndarray | torch.Tensor, joints=None,
                            count: int = 6, vmax: float = 1.0, title: str = "",
                            joint_names: Sequence[str] = JOINT_NAMES) -> Figure:
    """A film strip of ``count`` frames above the visual features of every step, on one time axis.

    ``frames`` (T, H, W, 3) uint8 and ``features`` (T, F) of the same steps,
    F = 3 x features per channel (R, G, B blocks, separated by white lines);
    dotted lines mark the steps of the strip. With ``joints`` (T, 5) a third
    panel plots them below, labelled with ``joint_names``. Colours span
    ``[-vmax, vmax]``.
    """
    frames, features = _numpy(frames), _numpy(features)
    steps = np.linspace(0, len(frames) - 1, count).round().astype(int)
    panels = 2 + (joints is not None)
    fig = plt.figure(figsize=(1.8 * count, 1.5 + 2.6 + 1.8 * (joints is not None)), layout="constrained")
    grid = fig.add_gridspec(panels, count, height_ratios=[1.5, 2.6, 1.8][:panels])
    for c, t in enumerate(steps):
        ax = fig.add_subplot(grid[0, c])
        ax.imshow(frames[t])
        ax.set(xticks=[], yticks=[])
        ax.set_title(f"t = {t}", fontsize=8)
    heat = fig.add_subplot(grid[1, :])
    im = heat.imshow(features.T, aspect="auto", cmap="RdBu_r", vmin=-vmax, vmax=vmax, interpolation="nearest",
                     extent=(-0.5, len(features) - 0.5, features.shape[1] - 0.5, -0.5))
    _feature_edges(heat, features.shape[1], horizontal=True)
    per = features.shape[1] // 3
    heat.set_yticks([per / 2 - 0.5, 1.5 * per - 0.5, 2.5 * per - 0.5], ["R", "G", "B"])
    heat.set_ylabel("feature")
    axes = [heat]
    if joints is not None:
        ax = fig.add_subplot(grid[2, :], sharex=heat)
        ax.plot(_numpy(joints), label=list(joint_names))
        ax.set(ylabel="joints (rad)")
        ax.legend(fontsize="x-small", ncol=len(joint_names), loc="best", framealpha=0.8)
        axes.append(ax)
    fig.colorbar(im, ax=axes, pad=0.01, fraction=0.03, label="feature value")  # one bar: the time axes stay aligned
    for ax in axes:
        for t in steps:
            ax.axvline(t, color="black", lw=0.8, ls=":")
    axes[-1].set_xlabel("time step")
    if title:
        fig.suptitle(title)
    return fig


def plot_feature_rows(frames: Mapping[str, np.ndarray], features: np.ndarray | torch.Tensor,
                      vmax: float = 1.0) -> Figure:
    """One frame per row (left) next to its visual features (right, one heat-map row, R | G | B blocks).

    ``frames`` maps a label to a frame (H, W, 3) uint8; ``features`` (N, F)
    holds the features of those frames in the same order. Colours span
    ``[-vmax, vmax]``.
    """
    features = _numpy(features)
    if len(frames) != len(features):
        raise ValueError(f"{len(frames)} frames but {len(features)} rows of features")
    n, width = len(frames), features.shape[1]
    fig, axes = plt.subplots(n, 2, figsize=(11, 0.95 * n + 0.8), squeeze=False, layout="constrained",
                             gridspec_kw={"width_ratios": [1, 5.5]})
    for r, (label, frame) in enumerate(frames.items()):
        axes[r, 0].imshow(_numpy(frame))
        axes[r, 0].set(xticks=[], yticks=[])
        axes[r, 0].set_ylabel(label, fontsize=8, rotation=0, ha="right", va="center")
        im = axes[r, 1].imshow(features[r:r + 1], aspect="auto", cmap="RdBu_r", vmin=-vmax, vmax=vmax,
                               interpolation="nearest")
        _feature_edges(axes[r, 1], width, horizontal=False)
        axes[r, 1].set(yticks=[], xticks=[])
    per = width // 3
    axes[-1, 1].set_xticks([per / 2 - 0.5, 1.5 * per - 0.5, 2.5 * per - 0.5],
                           ["R features", "G features", "B features"])
    fig.colorbar(im, ax=axes[:, 1], pad=0.01, fraction=0.03)
    return fig


def plot_vision(features: np.ndarray | torch.Tensor, length: int | None = None, title: str = "") -> Figure:
    """The 30 visual features of one sample over time as an image (10 per colour channel)."""
    features = _numpy(features)[:length or None]                 # (T, 30)
    fig, ax = plt.subplots(figsize=(7, 2.8))
    im = ax.imshow(features.T, aspect="auto", cmap="viridis", interpolation="nearest")
    for edge in (9.5, 19.5):                                     # R | G | B channel blocks
        ax.axhline(edge, color="white", lw=1)
    ax.set(xlabel="time step", ylabel="feature (R, G, B blocks)", title=title)
    fig.colorbar(im, ax=ax)
    fig.tight_layout()
    return fig


__all__ = ["CHANNEL_COLOURS", "plot_channels", "plot_reconstructions", "plot_cae_history", "plot_features_over_time",
           "plot_feature_rows", "plot_vision"]
