"""Chapter 06's ablation: the two-view model (Sec. 4, PGAE-self and PGAE-opposite) under three scalings.

The paper's PGAE-opposite describes 65.28% of the other agent's actions. ``benchmarks/opposite_scale.py``
trains the two-view model with each scaling of the visual features, on our data and on the authors',
and writes ``results/opposite_scale-ours.json`` and ``opposite_scale-original.json``; this module
measures how widely each scaling lets the opposite view vary (:func:`spread_of`) and reads the
result files into chapter 06's table (:func:`ablation_frame`).

- ``whiten``: the book's recipe, both views whitened with one transform and one scale;
- ``whiten-per-view``: the same, each view its own minimum and maximum;
- ``global``: the authors' code, no whitening, each view its own minimum and maximum.
"""
from __future__ import annotations

import numpy as np
import pandas as pd
import torch

from pgae_lite.data.dataset import Normaliser, PGAEDataset


def spread_of(data: PGAEDataset, scaling: str) -> float:
    """The opposite view's std over NICO's view's after ``scaling``, feature by feature, averaged.

    Fitted and measured on the valid steps of ``data``'s training split: 1 means the other agent's
    view varies as widely as NICO's own in the model's [-1, 1]; below 1, it is squeezed.
    """
    train_set = data.split("train")
    t = Normaliser.fit(train_set, scaling).tensors(train_set)
    valid = torch.from_numpy(train_set.mask)
    mine, theirs = t["vision"][valid].std(0), t["vision_opposite"][valid].std(0)      # (30,) each
    return float((theirs / mine).mean())


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


__all__ = ["ablation_frame", "spread_of"]
