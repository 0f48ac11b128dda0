"""Language spaces: similarities of word vectors and 2-D maps of sentence embeddings.

Paper, Sec. 3 and 5 (PGAE-BERT's pretrained language encoder). Helpers of the
PGAE-BERT chapter (05): a similarity matrix as an annotated heat map, and
sentence vectors on two axes, coloured by what they describe.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence

import matplotlib.pyplot as plt
import numpy as np
import torch
from matplotlib.figure import Figure

from pgae_lite.viz._common import _numpy

#: A display colour for each colour word of the dataset (canonical words).
WORD_COLOURS: dict[str, str] = {"red": "tab:red", "green": "tab:green", "blue": "tab:blue", "yellow": "gold",
                                "cyan": "darkturquoise", "violet": "darkviolet"}


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


__all__ = ["WORD_COLOURS", "plot_similarity", "plot_point_map"]
