"""Plots and tables for the book's chapters (matplotlib and pandas).

Every function returns its figure (or DataFrame) and shows nothing itself:
a notebook displays what a cell returns, a script may save it. Nothing here
changes the model or the data.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import torch
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from .data import PGAEDataset, description_text
from .language import CANONICAL, SIGNALS, SLOT_NAMES, VOCABULARY
from .signals import SignalBatch

#: One colour per signal, the same in every figure of the book.
SIGNAL_COLOURS: dict[str, str] = {
    "describe": "tab:blue", "execute": "tab:orange", "repeat action": "tab:green",
    "repeat both": "tab:purple", "repeat language": "tab:red"}
JOINT_NAMES: tuple[str, ...] = tuple(f"joint {k}" for k in range(1, 6))


def _numpy(x) -> np.ndarray:
    return x.detach().cpu().numpy() if isinstance(x, torch.Tensor) else np.asarray(x)


def plot_gates(gates_by_signal: Mapping[str, np.ndarray | torch.Tensor], title: str = "GMU gate z") -> Figure:
    """Mean GMU gate per signal (bars, ± one standard deviation) and per dimension (heat map).

    ``gates_by_signal`` maps a signal name to gate values of shape (N, hidden),
    e.g. ``{s: p.gate for s, p in predictions.items()}`` from
    :func:`pgae_lite.evaluate.evaluate`. z near 1 lets the action features
    through, z near 0 the language features (h = z ⊙ A_h + (1 − z) ⊙ L_h).
    """
    names = list(gates_by_signal)
    gates = [_numpy(gates_by_signal[s]).reshape(-1, _numpy(gates_by_signal[s]).shape[-1]) for s in names]
    fig, (bars, heat) = plt.subplots(1, 2, figsize=(11, 0.5 * len(names) + 2.2),
                                     gridspec_kw={"width_ratios": [1, 2.2]})
    means = [g.mean() for g in gates]
    stds = [g.mean(1).std() for g in gates]                     # spread over samples
    y = np.arange(len(names))
    bars.barh(y, means, xerr=stds, color=[SIGNAL_COLOURS.get(s, "grey") for s in names])
    bars.axvline(0.5, color="black", lw=0.8, ls=":")
    bars.set(yticks=y, yticklabels=names, xlim=(0, 1), xlabel="mean z (0 = language, 1 = action)")
    bars.invert_yaxis()
    per_dim = np.stack([g.mean(0) for g in gates])              # (signals, hidden)
    im = heat.imshow(per_dim, aspect="auto", cmap="coolwarm", vmin=0, vmax=1, interpolation="nearest")
    heat.set(yticks=y, yticklabels=names, xlabel="dimension of h")
    fig.colorbar(im, ax=heat, label="mean z")
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_joints(pred: np.ndarray | torch.Tensor, target: np.ndarray | torch.Tensor,
                length: int | None = None, title: str = "", ax: plt.Axes | None = None) -> Figure:
    """The 5 joint angles over time: recorded (solid) and predicted (dashed).

    ``pred`` and ``target`` have shape (T, 5); steps at or past ``length`` (or
    NaN) are not drawn.
    """
    pred, target = _numpy(pred), _numpy(target)
    length = length or len(target)
    if ax is None:
        fig, ax = plt.subplots(figsize=(6, 3.2))
    else:
        fig = ax.figure
    steps = np.arange(length)
    for k in range(target.shape[1]):
        colour = f"C{k}"
        ax.plot(steps, target[:length, k], color=colour, lw=2, alpha=0.5, label=JOINT_NAMES[k])
        ax.plot(steps, pred[:length, k], color=colour, lw=1.2, ls="--")
    ax.plot([], [], color="grey", lw=2, alpha=0.5, label="recorded")
    ax.plot([], [], color="grey", lw=1.2, ls="--", label="predicted")
    ax.set(xlabel="time step", ylabel="joint value", title=title)
    ax.legend(fontsize="small", ncol=2, loc="best")
    fig.tight_layout()
    return fig


def plot_history(history: Sequence[Mapping]) -> Figure:
    """Training curves from ``Trained.history``: losses (log scale) and the mean gate per signal."""
    epochs = [r["epoch"] for r in history]
    fig, (loss_ax, gate_ax) = plt.subplots(1, 2, figsize=(11, 3.6))
    for key, label in (("loss", "total"), ("language_loss", "language (weighted CE)"),
                       ("action_loss", "action (MSE)")):
        loss_ax.plot(epochs, [r[key] for r in history], label=label, marker="." if len(epochs) < 10 else None)
    loss_ax.set(yscale="log", xlabel="epoch", ylabel="training loss", title="Loss")
    loss_ax.legend()
    for s in SIGNALS:
        points = [(r["epoch"], r["gate"][s]) for r in history if s in r["gate"]]
        if points:
            x, z = zip(*points)
            gate_ax.plot(x, z, label=s, color=SIGNAL_COLOURS[s], marker="." if len(x) < 10 else None)
    gate_ax.axhline(0.5, color="black", lw=0.8, ls=":")
    gate_ax.set(ylim=(0, 1), xlabel="epoch", ylabel="mean z", title="Mean GMU gate per signal (training)")
    gate_ax.legend(fontsize="small")
    for ax in (loss_ax, gate_ax):
        ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    fig.tight_layout()
    return fig


def _words(tokens: Sequence[int]) -> str:
    """Token indices of the 28-d input space -> text; signal tokens in brackets."""
    out = []
    for t in tokens:
        t = int(t)
        out.append(f"[{SIGNALS[t - len(VOCABULARY)]}]" if t >= len(VOCABULARY) else VOCABULARY[t])
    return " ".join(out)


def signal_table(batch: SignalBatch) -> pd.DataFrame:
    """One row per sample of ``batch``: what goes into the encoders and what the decoders must produce.

    Build ``batch`` with :func:`pgae_lite.signals.make_batch`, e.g. one sample
    under each of the five signals, to get the paper's "Signals" list as a table.
    """
    rows = []
    for i in range(len(batch.signal)):
        n_lang, n_act = int(batch.lang_lengths[i]), int(batch.action_lengths[i])
        steps = int(batch.joint_mask[i].sum()) + 1              # recorded steps of the sample
        target = batch.joint_target[i, :steps - 1]              # (steps-1, 5)
        held = bool(torch.allclose(target, batch.start_joints[i].expand_as(target)))
        first = batch.action_input[i, 0, -batch.start_joints.shape[1]:]
        if held:
            pose = "first" if torch.allclose(batch.start_joints[i], first) else "final"
            action_out = f"{pose} pose, held for {steps} steps"
        else:
            action_out = f"recorded sequence, {steps} steps"
        lang_out = _words(batch.lang_target[i][batch.lang_mask[i]].tolist()).replace(VOCABULARY[0], "<EOS>")
        rows.append({
            "signal": SIGNALS[int(batch.signal[i])],
            "language input": _words(batch.lang_tokens[i, :n_lang].tolist()).replace(VOCABULARY[0], "<EOS>"),
            "action input": f"whole sequence ({n_act} steps)" if n_act > 1 else "first step only",
            "language target": lang_out,
            "action target": action_out,
        })
    return pd.DataFrame(rows).set_index("signal")


def wrong_words(expected: str, generated: str) -> str:
    """Which of action / colour / speed differ ("" when none; synonyms count as equal).

    A generated text of another length than the expected one gives e.g. ``"2 words"``.
    """
    e, g = expected.split(), generated.split()
    if len(g) != len(e):
        return f"{len(g)} word{'s' * (len(g) != 1)}" if g else "<EOS> only"
    return ", ".join(n for n, a, b in zip(SLOT_NAMES, e, g) if CANONICAL[a] != CANONICAL.get(b))


def prediction_frame(pred, data: PGAEDataset) -> pd.DataFrame:
    """One row per sample of a :class:`pgae_lite.evaluate.Predictions` on ``data`` (same order).

    Columns: id, code (the authors' label, e.g. ``PUSH-L-SLOW``), action, side,
    speed, arrangement, expected (the first of the 8 descriptions, or "" where
    the signal expects ``<EOS>`` alone), generated, correct, and wrong (which
    words of a wrong description are wrong). Group it for an error analysis,
    e.g. ``frame.groupby("action").correct.mean()``.
    """
    code = pd.Series(np.asarray(data.action), dtype=str)
    parts = code.str.split("-")
    says_words = pred.signal in ("describe", "repeat language", "repeat both")
    expected = [description_text(d[0]) if says_words else "" for d in data.descriptions]
    return pd.DataFrame({
        "id": np.asarray(data.ids),
        "code": code,
        "action": parts.str[0].str.lower(),
        "side": parts.str[1].map({"L": "left cube", "R": "right cube"}),
        "speed": parts.str[2].str.lower(),
        "arrangement": np.asarray(data.arrangement),
        "expected": expected,
        "generated": list(pred.text),
        "correct": np.asarray(pred.correct, dtype=bool),
        "wrong": ["" if ok else wrong_words(e, g) for ok, e, g in zip(pred.correct, expected, pred.text)],
    })


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


__all__ = ["plot_gates", "plot_joints", "plot_history", "signal_table", "prediction_frame", "wrong_words", "plot_vision",
           "SIGNAL_COLOURS"]


# --------------------------------------------------------------------------- the world: frames, animations, patterns
# Helpers of the simulator and dataset chapters (01, 02), also meant for later ones:
# film strips and animations of recorded frames, the 144 patterns as a grid, and
# joint trajectories grouped by action.

def plot_frames(rows: Mapping[str, np.ndarray], count: int = 6, size: float = 1.7) -> Figure:
    """Film strips: ``count`` evenly spaced frames of each sequence, one row per entry of ``rows``.

    ``rows`` maps a label to frames (T, H, W, 3) uint8, e.g. ``{"NICO acts": ep.images}``;
    each row spans its own sequence from the first to the last frame, and each
    frame is titled with its time step.
    """
    rows = {label: np.asarray(frames) for label, frames in rows.items()}
    if not rows:
        raise ValueError("rows is empty: pass at least one named frame sequence (T, H, W, 3)")
    height, width = next(iter(rows.values())).shape[1:3]
    fig, axes = plt.subplots(len(rows), count, squeeze=False,
                             figsize=(count * size, len(rows) * (size * height / width + 0.3)))
    for r, (label, frames) in enumerate(rows.items()):
        for ax, t in zip(axes[r], np.linspace(0, len(frames) - 1, count).round().astype(int)):
            ax.imshow(frames[t])
            ax.set(xticks=[], yticks=[])
            ax.set_title(f"t = {t}", fontsize=8)
        axes[r, 0].set_ylabel(label, fontsize=9)
    fig.tight_layout()
    return fig


def animate_frames(views: Mapping[str, np.ndarray], joints: np.ndarray | None = None, every: int = 2,
                   fps: float = 10.0, size: float = 2.8, dpi: int = 72, title: str = ""):
    """An animation of frame sequences side by side (one panel per entry of ``views``).

    ``views`` maps a label to frames (T, H, W, 3) uint8; every ``every``-th step
    is drawn (a shorter sequence holds its last frame). With ``joints`` (T, 5)
    a last panel plots them with a cursor at the current step. Returns a
    ``matplotlib.animation.FuncAnimation``; show it with
    ``IPython.display.HTML(anim.to_jshtml())``, which embeds every frame as a
    PNG image, so it plays offline. Its size grows with the number of frames
    and with ``size`` and ``dpi``: keep them small. The figure is closed, so a
    notebook does not also show it as a still image.
    """
    from matplotlib.animation import FuncAnimation

    views = {label: np.asarray(frames) for label, frames in views.items()}
    if not views:
        raise ValueError("views is empty: pass at least one named frame sequence (T, H, W, 3)")
    length = max(len(frames) for frames in views.values())
    steps = list(range(0, length, every)) + ([length - 1] if (length - 1) % every else [])
    height, width = next(iter(views.values())).shape[1:3]
    panels = len(views) + (joints is not None)
    fig, axes = plt.subplots(1, panels, figsize=(panels * size, size * height / width + 0.45), dpi=dpi,
                             squeeze=False)
    images = []
    for ax, (label, frames) in zip(axes[0], views.items()):
        images.append(ax.imshow(frames[0]))
        ax.set_title(label, fontsize=9)
        ax.axis("off")
    artists: list = list(images)
    if joints is not None:
        ax = axes[0, -1]
        ax.plot(_numpy(joints))
        cursor = ax.axvline(0, color="black", lw=1)
        ax.set_title("joints (rad)", fontsize=9)
        ax.tick_params(labelsize=7)
        artists.append(cursor)
    label = fig.suptitle(title, fontsize=9)
    fig.tight_layout()

    def draw(t: int) -> list:
        for image, frames in zip(images, views.values()):
            image.set_data(frames[min(t, len(frames) - 1)])
        if joints is not None:
            cursor.set_xdata([t, t])
        label.set_text(f"{title}   step {t}".strip())
        return artists + [label]

    anim = FuncAnimation(fig, draw, frames=steps, interval=1000.0 / fps, blit=False)
    plt.close(fig)
    return anim


def plot_patterns(values: Mapping[int, float] | None = None, marked: Sequence[int] | frozenset[int] | None = None,
                  label: str = "", title: str = "The 144 patterns", cmap: str = "viridis") -> Figure:
    """The 144 patterns as a grid: 12 arrangements (rows) x 12 actions (columns, 6 slow then 6 fast).

    The cell of pattern ``72·speed + 6·arrangement + action`` is in row
    ``arrangement`` and column ``6·speed + action``, labelled with its number.
    Without ``values`` a cell is dark for a test pattern
    (:data:`pgae_lite.data.TEST_PATTERNS`) and light for a training one; with
    ``values`` (pattern -> number, e.g. accuracy per pattern, ``label`` names
    it) the cells are coloured by value, missing ones blank, and test
    patterns are outlined. ``marked`` patterns (e.g. a profile's subset) get
    a black dot.
    """
    from .data import ACTION_SIDES, ARRANGEMENTS, TEST_PATTERNS

    grid = np.full((12, 12), np.nan)
    for number in range(144):
        speed, rest = divmod(number, 72)
        row, col = divmod(rest, 6)
        if values is None:
            grid[row, 6 * speed + col] = number in TEST_PATTERNS
        elif number in values:
            grid[row, 6 * speed + col] = values[number]
    fig, ax = plt.subplots(figsize=(9.5, 6.2))
    if values is None:
        ax.imshow(grid, cmap=plt.matplotlib.colors.ListedColormap(["#dfe7f2", "#e4572e"]), vmin=0, vmax=1)
        ax.plot([], [], "s", color="#e4572e", mec="grey", ms=9, label="test pattern")
        ax.plot([], [], "s", color="#dfe7f2", mec="grey", ms=9, label="training pattern")
    else:
        im = ax.imshow(np.ma.masked_invalid(grid), cmap=cmap)
        fig.colorbar(im, ax=ax, label=label, shrink=0.8)
        ax.plot([], [], "s", mfc="none", mec="black", mew=2, label="test pattern")
    for number in range(144):
        speed, rest = divmod(number, 72)
        row, col = divmod(rest, 6)
        x = 6 * speed + col
        if values is not None and number in TEST_PATTERNS:
            ax.add_patch(plt.Rectangle((x - 0.5, row - 0.5), 1, 1, fill=False, lw=2, ec="black"))
        ax.text(x, row + 0.22, str(number), ha="center", va="center", fontsize=6.5, color="#333333")
        if marked is not None and number in marked:
            ax.plot(x, row - 0.15, "o", color="black", ms=3.5)
    if marked is not None:
        ax.plot([], [], "o", color="black", ms=3.5, label="in this profile")
    ax.set_xticks(range(12), [f"{a} {s}" for _ in range(2) for a, s in ACTION_SIDES], rotation=45, ha="right")
    ax.set_yticks(range(12), [f"{left}+{right}" for left, right in ARRANGEMENTS])
    ax.axvline(5.5, color="black", lw=1.5)
    ax.text(2.5, -0.9, "slowly (100 steps)", ha="center")
    ax.text(8.5, -0.9, "fast (50 steps)", ha="center")
    ax.axhline(5.5, color="black", lw=0.8, ls=":")
    ax.set(xlabel="action (cube side L / R, seen by NICO)", ylabel="arrangement (left+right cube)")
    ax.set_title(title, pad=22)
    ax.legend(loc="upper left", bbox_to_anchor=(1.0 if values is None else 1.25, 1.0), fontsize="small")
    fig.tight_layout()
    return fig


def plot_joints_by_action(joints: Sequence[np.ndarray], codes: Sequence[str],
                          joint_names: Sequence[str] = JOINT_NAMES, alpha: float = 0.4) -> Figure:
    """Joint trajectories grouped by action: one panel per action code, all samples overlaid.

    ``joints`` holds one (T, 5) array per sample (valid steps only, e.g.
    ``[j[:n] for j, n in zip(data.joints, data.lengths)]``) and ``codes`` its
    action code such as ``PUSH-L-SLOW``. Rows: slow, fast; columns: push,
    pull, slide of the left cube, then of the right cube. Joint k is drawn in
    colour Ck in every panel.
    """
    from .data import ACTION_SIDES

    columns = [f"{a.upper()}-{s}" for a, s in ACTION_SIDES]
    fig, axes = plt.subplots(2, 6, figsize=(15, 5.2), sharey=True)
    for trajectory, code in zip(joints, codes):
        action, side, speed = str(code).split("-")
        ax = axes[int(speed == "FAST"), columns.index(f"{action}-{side}")]
        trajectory = _numpy(trajectory)
        for k in range(trajectory.shape[1]):
            ax.plot(trajectory[:, k], color=f"C{k}", lw=1, alpha=alpha)
    for r, speed in enumerate(("slow", "fast")):
        for c, column in enumerate(columns):
            action, side = column.split("-")
            ax = axes[r, c]
            ax.set_title(f"{action.lower()} {'left' if side == 'L' else 'right'}, {speed}", fontsize=9)
            ax.set_xlim(0, 100 if speed == "slow" else 50)
            if r == 1:
                ax.set_xlabel("time step")
        axes[r, 0].set_ylabel("joint angle (rad)")
    for k, name in enumerate(joint_names):
        axes[0, 0].plot([], [], color=f"C{k}", label=name)
    fig.legend(loc="lower center", ncol=len(joint_names), fontsize="small", bbox_to_anchor=(0.5, -0.01))
    fig.tight_layout(rect=(0, 0.05, 1, 1))
    return fig


__all__ += ["plot_frames", "animate_frames", "plot_patterns", "plot_joints_by_action"]


# --------------------------------------------------------------------------- seeing: images and visual features
# Helpers of the CAE chapter (03), also meant for later ones: a frame split into
# its colour channels, reconstructions next to originals, the CAE's training
# curves, and the 30 visual features next to the frames they come from.

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
    axes[-1, 1].set_xticks([per / 2 - 0.5, 1.5 * per - 0.5, 2.5 * per - 0.5], ["R features", "G features", "B features"])
    fig.colorbar(im, ax=axes[:, 1], pad=0.01, fraction=0.03)
    return fig


__all__ += ["CHANNEL_COLOURS", "plot_channels", "plot_reconstructions", "plot_cae_history", "plot_features_over_time",
            "plot_feature_rows"]


# --------------------------------------------------------------------------- variants: models, views, embeddings
# Helpers of the PGAE-BERT and opposite-agent chapters (05, 06): training curves and
# gates of several models side by side, which words a model confuses, and maps of
# sentence embeddings.

#: A display colour for each colour word of the dataset (canonical words).
WORD_COLOURS: dict[str, str] = {"red": "tab:red", "green": "tab:green", "blue": "tab:blue", "yellow": "gold",
                                "cyan": "darkturquoise", "violet": "darkviolet"}


def plot_histories(histories: Mapping[str, Sequence[Mapping]],
                   keys: Sequence[str] = ("language_loss", "action_loss")) -> Figure:
    """Training curves of several runs on shared axes: one panel per loss, one line per run.

    ``histories`` maps a run's name to its ``Trained.history``, e.g.
    ``{"PGAE": pgae.history, "PGAE-BERT": bert.history}``; ``keys`` are the
    history's loss entries to draw (log scale).
    """
    titles = {"loss": "total loss", "language_loss": "language loss (weighted CE)", "action_loss": "action loss (MSE)"}
    fig, axes = plt.subplots(1, len(keys), figsize=(5.5 * len(keys), 3.4), squeeze=False)
    for ax, key in zip(axes[0], keys):
        for k, (name, history) in enumerate(histories.items()):
            epochs = [r["epoch"] for r in history]
            ax.plot(epochs, [r[key] for r in history], color=f"C{k}", label=name,
                    marker="." if len(epochs) < 10 else None)
        ax.set(yscale="log", xlabel="epoch", ylabel="training loss", title=titles.get(key, key))
        ax.xaxis.set_major_locator(MaxNLocator(integer=True))
        ax.legend(fontsize="small")
    fig.tight_layout()
    return fig


def plot_mean_gates(groups: Mapping[str, Mapping[str, np.ndarray | torch.Tensor]],
                    title: str = "Mean GMU gate per signal") -> Figure:
    """Mean GMU gate per signal for several models or views, as grouped bars (± one standard deviation).

    ``groups`` maps a group name (a model, a view) to ``{signal: gate values (N, hidden)}``,
    e.g. ``{"PGAE": {s: p.gate for s, p in preds.items()}, ...}``; a signal missing
    from a group leaves a gap. The spread is that of the per-sample mean gate.
    z near 1 lets the action features through, z near 0 the language features.
    """
    signals = list(dict.fromkeys(s for gates in groups.values() for s in gates))
    width = 0.8 / max(1, len(groups))
    fig, ax = plt.subplots(figsize=(1.6 * len(signals) + 3, 3.4))
    x = np.arange(len(signals))
    for k, (name, gates) in enumerate(groups.items()):
        per_sample = {s: _numpy(g).reshape(-1, _numpy(g).shape[-1]).mean(1) for s, g in gates.items()}
        means = [per_sample[s].mean() if s in per_sample else np.nan for s in signals]
        stds = [per_sample[s].std() if s in per_sample else 0.0 for s in signals]
        ax.bar(x + (k - (len(groups) - 1) / 2) * width, means, width, yerr=stds, label=name, color=f"C{k}",
               capsize=2)
    ax.axhline(0.5, color="black", lw=0.8, ls=":")
    ax.set(xticks=x, ylim=(0, 1), ylabel="mean z (0 = language, 1 = action)", title=title)
    ax.set_xticklabels(signals)
    ax.legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.0, 1.0))
    fig.tight_layout()
    return fig


def word_confusion(pred, data: PGAEDataset, slot: str = "action") -> pd.DataFrame:
    """Counts of expected (rows) against generated (columns) word at one position of a description.

    ``pred`` is a :class:`pgae_lite.evaluate.Predictions` of a signal that outputs a
    description (``describe``, ``repeat language``) on ``data`` (same order); ``slot``
    is ``"action"``, ``"colour"`` or ``"speed"``. Words are counted as their canonical
    form (``move-up`` counts as ``push``). A generated text with too few words or a
    word that cannot stand at that position counts as ``"other"``.
    """
    from .language import SLOTS

    k = SLOT_NAMES.index(slot)
    words = list(SLOTS[k])
    expected = [CANONICAL[VOCABULARY[int(d[0, k])]] for d in data.descriptions]
    generated = []
    for text in pred.text:
        parts = text.split()
        word = CANONICAL.get(parts[k]) if len(parts) > k else None
        generated.append(word if word in words else "other")
    table = pd.crosstab(pd.Categorical(expected, categories=words),
                        pd.Categorical(generated, categories=[*words, "other"]), dropna=False)
    table.index.name, table.columns.name = "expected", "generated"
    return table


def plot_word_confusion(preds: Mapping[str, object], data: PGAEDataset,
                        slots: Sequence[str] = SLOT_NAMES, title: str = "") -> Figure:
    """Confusion tables of :func:`word_confusion` as annotated heat maps: a row per entry, a column per slot.

    ``preds`` maps a label (a view, a model) to its ``Predictions`` on ``data``,
    e.g. ``{"NICO's view": self_preds["describe"], "opposite view": opp_preds["describe"]}``.
    Each row of a table is normalised to the fraction of its samples; the counts are written in the cells.
    """
    fig, axes = plt.subplots(len(preds), len(slots), squeeze=False,
                             figsize=(3.4 * len(slots) + 1, 2.9 * len(preds)),
                             gridspec_kw={"width_ratios": [3 + (s == "colour") * 3 for s in slots]})
    for r, (label, pred) in enumerate(preds.items()):
        for c, slot in enumerate(slots):
            table = word_confusion(pred, data, slot)
            counts = table.to_numpy()
            share = counts / np.maximum(counts.sum(1, keepdims=True), 1)
            ax = axes[r, c]
            ax.imshow(share, cmap="Blues", vmin=0, vmax=1, aspect="auto")
            for (i, j), n in np.ndenumerate(counts):
                if n:
                    ax.text(j, i, str(n), ha="center", va="center", fontsize=8,
                            color="white" if share[i, j] > 0.6 else "black")
            ax.set_xticks(range(counts.shape[1]), table.columns, rotation=45, ha="right", fontsize=8)
            ax.set_yticks(range(counts.shape[0]), table.index, fontsize=8)
            ax.set_title(f"{label}: {slot}" if label else slot, fontsize=9)
            if c == 0:
                ax.set_ylabel("expected")
            if r == len(preds) - 1:
                ax.set_xlabel("generated")
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_similarity(similarity: np.ndarray | torch.Tensor, labels: Sequence[str], title: str = "",
                    groups: Sequence[int] = ()) -> Figure:
    """A square similarity matrix (e.g. cosine similarities of word vectors) as an annotated heat map.

    ``labels`` name the rows and columns; ``groups`` are the indices at which a new
    group starts (e.g. ``[6, 18]`` between the action, colour and speed words), drawn as lines.
    """
    similarity = _numpy(similarity)
    n = len(labels)
    fig, ax = plt.subplots(figsize=(0.36 * n + 2.5, 0.36 * n + 1.2))
    im = ax.imshow(similarity, cmap="viridis", vmin=min(0.0, float(similarity.min())), vmax=1)
    for (i, j), s in np.ndenumerate(similarity):
        ax.text(j, i, f"{s:.1f}".lstrip("0").replace("-0", "-"), ha="center", va="center", fontsize=6,
                color="black" if s > 0.6 else "white")
    for g in groups:
        ax.axhline(g - 0.5, color="white", lw=1.5)
        ax.axvline(g - 0.5, color="white", lw=1.5)
    ax.set_xticks(range(n), labels, rotation=90, fontsize=8)
    ax.set_yticks(range(n), labels, fontsize=8)
    ax.set_title(title)
    fig.colorbar(im, ax=ax, fraction=0.04, pad=0.02, label="cosine similarity")
    fig.tight_layout()
    return fig


def plot_point_map(xy: np.ndarray | torch.Tensor, labellings: Mapping[str, Sequence[str]],
                   colours: Mapping[str, str] | None = None, title: str = "",
                   axis_labels: tuple[str, str] = ("PC 1", "PC 2")) -> Figure:
    """The same 2-D points several times, coloured by one labelling per panel.

    ``xy`` (N, 2), e.g. the first two principal components of sentence vectors;
    ``labellings`` maps a panel title to a label per point, e.g.
    ``{"action": [...], "colour": [...], "speed": [...]}``. A label found in
    ``colours`` (default :data:`WORD_COLOURS`) gets that colour, others the default cycle.
    """
    xy = _numpy(xy)
    colours = WORD_COLOURS if colours is None else colours
    fig, axes = plt.subplots(1, len(labellings), figsize=(4.2 * len(labellings), 3.8), squeeze=False,
                             sharex=True, sharey=True)
    for ax, (name, labels) in zip(axes[0], labellings.items()):
        labels = np.asarray(labels)
        for k, value in enumerate(dict.fromkeys(labels.tolist())):
            on = labels == value
            ax.scatter(*xy[on].T, s=12, alpha=0.75, color=colours.get(value, f"C{k}"), label=value)
        ax.set(title=f"coloured by {name}", xlabel=axis_labels[0])
        ax.legend(fontsize=7, markerscale=1.5, loc="best")
    axes[0, 0].set_ylabel(axis_labels[1])
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig


__all__ += ["WORD_COLOURS", "plot_histories", "plot_mean_gates", "word_confusion", "plot_word_confusion",
            "plot_similarity", "plot_point_map"]
