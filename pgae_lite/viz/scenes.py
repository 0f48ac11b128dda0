"""The world: film strips and animations of recorded frames, the 144 patterns, joints by action.

Paper, Sec. 4 (Dataset) on our own simulator. Helpers of the simulator and
dataset chapters (01, 02), also meant for later ones: film strips and
animations of recorded frames, the 144 patterns as a grid, and joint
trajectories grouped by action.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.figure import Figure

from pgae_lite.viz._common import JOINT_NAMES, _numpy
from pgae_lite.world.patterns import ACTION_SIDES, ARRANGEMENTS, TEST_PATTERNS, pattern_parts


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
    (:data:`pgae_lite.world.patterns.TEST_PATTERNS`) and light for a training one; with
    ``values`` (pattern -> number, e.g. accuracy per pattern, ``label`` names
    it) the cells are coloured by value, missing ones blank, and test
    patterns are outlined. ``marked`` patterns (e.g. a profile's subset) get
    a black dot.
    """
    grid = np.full((12, 12), np.nan)
    for number in range(144):
        speed, row, col = pattern_parts(number)
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
        speed, row, col = pattern_parts(number)
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


__all__ = ["plot_frames", "animate_frames", "plot_patterns", "plot_joints_by_action"]
