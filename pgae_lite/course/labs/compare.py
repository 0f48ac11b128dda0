"""A lab's result beside its references: the student's run and the committed runs over three seeds.

Not in the paper. ``benchmarks/labs.py`` writes ``results/lab-NAME.json``: the lab's run on the book's
component (``baseline``) and on the reference change (``reference``), once per seed. :func:`reference_table`
gives those figures, a row per variant and seed; :func:`compare` draws each figure's references as points
and the student's own run as a line across them, so the student sees whether the change they made moved the
figure beyond the spread of the seeds.
"""
from __future__ import annotations

import matplotlib.pyplot as plt
import pandas as pd

from pgae_lite.runs.results import load

VARIANTS = {"baseline": "the book's component", "reference": "the reference change"}


def reference_table(name: str) -> pd.DataFrame:
    """The committed runs of lab ``name``: one row per variant and seed, a column per figure, and seconds."""
    runs = load(f"lab-{name}")["data"]["runs"]
    rows = [{"variant": VARIANTS[r["variant"]], "seed": r["seed"], **r["figures"], "seconds": r["seconds"]}
            for r in runs]
    return pd.DataFrame(rows).set_index(["variant", "seed"]).sort_index()


def compare(name: str, student: dict[str, float] | None = None, label: str = "your run"):
    """One panel per figure of lab ``name``: the references' seeds as points, ``student``'s figures as lines."""
    data = load(f"lab-{name}")["data"]
    figures = data["figures"]                                   # {key: label}
    fig, axes = plt.subplots(1, len(figures), figsize=(3.2 * len(figures), 2.8), squeeze=False)
    for ax, (key, title) in zip(axes[0], figures.items()):
        for x, variant in enumerate(VARIANTS):
            ys = [r["figures"][key] for r in data["runs"] if r["variant"] == variant]
            ax.scatter([x] * len(ys), ys, color=f"C{x}", zorder=3)
        if student is not None and key in student:
            ax.axhline(float(student[key]), color="C3", linestyle="--", label=label)
            ax.legend(loc="best", fontsize=8)
        ax.set_xticks(range(len(VARIANTS)), ["book", "change"])
        ax.set_xlim(-0.6, len(VARIANTS) - 0.4)
        ax.set_title(title, fontsize=9)
    fig.suptitle(f"{data['title']}: three seeds each, and your run", fontsize=10)
    fig.tight_layout()
    return fig
