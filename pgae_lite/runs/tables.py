"""The chapters' tables of committed result files: the family's (chapter 09, A2) and the two-view ablation (06, A2).

PGAE paper, Sec. 2 and 4 (PRAE, PVAE, N.A.), PTAE's experiments, and Sec. 4's PGAE-self and
PGAE-opposite. Each reads a file that a benchmark wrote (:mod:`pgae_lite.runs.results`):

- ``family-original`` / ``family-ours`` (``benchmarks/family.py``): :func:`family_frame`;
- ``limited_supervision`` (``benchmarks/limited_supervision.py``): :func:`limited_frame`;
- ``incongruent`` (``benchmarks/incongruent.py``): :func:`conflict_frames`;
- ``opposite_scale-original`` / ``-ours`` (``benchmarks/opposite_scale.py``: the two-view model under three
  scalings of the visual features, each view's spread by :func:`pgae_lite.data.normaliser.spread_of`):
  :func:`ablation_frame`.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from pgae_lite.runs import results
from pgae_lite.world.words import TEST_SIGNALS

MEASURES = (("words %", "accuracy", ".2f"), ("nRMSE %", "nrmse", ".3f"))


def cell_text(stats: dict | None, fmt: str) -> str:
    """A cell's median with the worst and best seed, ``"N.A."`` where the model cannot produce it."""
    if stats is None:
        return "N.A."
    return f"{stats['median']:{fmt}} [{stats['min']:{fmt}}, {stats['max']:{fmt}}]"


def family_frame(source: str, result: str | None = None) -> pd.DataFrame:
    """The family table on ``source`` (``"original"`` or ``"ours"``): a row per model, each task's words and
    nRMSE, the median training time (s) and the trainable parameters. ``result``: another result file of
    ``benchmarks/family.py`` than ``family-SOURCE`` (e.g. ``"family_length_batches"``)."""
    out = {}
    for name, row in results.value(result or f"family-{source}", "rows").items():
        line = {(signal, what): cell_text(row["stats"][signal][key], fmt)
                for signal in TEST_SIGNALS for what, key, fmt in MEASURES}
        line[("", "time (s)")] = f"{np.median(row['train_seconds']):.0f}"
        line[("", "parameters")] = f"{row['parameters']:,}"
        out[name] = line
    return pd.DataFrame(out).T


def limited_frame() -> pd.DataFrame:
    """Limited supervision: a row per (model, reading, share); describe accuracy and execute nRMSE."""
    rows = {(r["model"], r["reading"], f"{100 * r['share']:g}%"): {
        "describe words %": cell_text(r["stats"]["describe"]["accuracy"], ".2f"),
        "execute nRMSE %": cell_text(r["stats"]["execute"]["nrmse"], ".3f")}
        for r in results.value("limited_supervision", "table")}
    return pd.DataFrame(rows).T.rename_axis(["model", "supervised", "share"])


def conflict_frames() -> tuple[pd.DataFrame, pd.DataFrame]:
    """Incongruent input: the language conflicts (describe, %) and the action conflicts (execute, nRMSE %),
    a column per model and measure, a row per conflict (``none``: the congruent input), medians."""
    medians = results.value("incongruent", "medians")
    language = pd.DataFrame({(m, what): {kind: round(v[what], 2) for kind, v in c["language"].items()}
                             for m, c in medians.items() for what in ("described right", "said the words read")})
    action = pd.DataFrame({(m, what): {kind: round(v[what], 3) for kind, v in c["action"].items()}
                           for m, c in medians.items() for what in ("nrmse to the described", "nrmse to the shown")})
    return (language.rename_axis("language conflict (describe, %)"),
            action.rename_axis("action conflict (execute, nRMSE %)"))


def _median_range(values: list[float]) -> str:
    return f"{np.median(values):.1f} ({min(values):.1f}-{max(values):.1f})"


def ablation_frame(runs: dict[str, list[dict]], labels: dict[str, str]) -> pd.DataFrame:
    """One row per (dataset, scaling): describe on both views (median and range over the seeds), spread.

    ``runs``: the ``runs`` of each result file by dataset ("original", "ours"); ``labels``: each
    scaling's name in the table, in the table's order.
    """
    named = {"original": "the authors' data", "ours": "our data"}
    rows = []
    for source, mine in runs.items():
        for scaling, label in labels.items():
            chosen = [r for r in mine if r["scaling"] == scaling]
            if not chosen:
                continue
            rows.append({"data": named.get(source, source), "scaling": label, "seeds": len(chosen),
                         "PGAE-self describe (%)": _median_range(
                             [r["table1"]["self"]["describe"]["accuracy"] for r in chosen]),
                         "PGAE-opposite describe (%)": _median_range(
                             [r["table1"]["opposite"]["describe"]["accuracy"] for r in chosen]),
                         "spread": round(chosen[0]["opposite_spread"], 2)})
    return pd.DataFrame(rows).set_index(["data", "scaling"])


__all__ = ["ablation_frame", "cell_text", "conflict_frames", "family_frame", "limited_frame"]
