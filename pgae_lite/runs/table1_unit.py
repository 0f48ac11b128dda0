"""One unit of a Table 1 sweep: one training for one seed, trained (or resumed), then measured on its rows.

Any row of :mod:`pgae_lite.runs.rows`, Table 1's or the family's: the model is trained by the one loop
into ``OUT/TRAINING-seedS`` (:func:`~pgae_lite.runs.pipeline.train_when_free`: a later run with the same
recipe and data loads it) and measured by the one evaluation, N.A. where it has no path.

Paper, Sec. 4 and Table 1. ``reproduce`` over seeds is a list of these units, run one after
another in this process or as tasks on a Dask cluster (:mod:`pgae_lite.runs.sweep`). A unit
runs wherever its worker is, so it finds its data there (:func:`~pgae_lite.runs.data.loaded`: the authors'
folder at the same path, a shared disk or a copy at that path; or this profile's simulated data from the
worker's own cache, recorded and encoded there if missing). It
returns everything the report needs (cells, predictions, training time) and the data
statistics its model was trained on, which the sweep's caller checks against its own data
(:func:`check_made_on`): a worker whose CAE gave other features fails the sweep with a
:class:`~pgae_lite.train.checkpoint.DataMismatchError`, never a silently wrong cell.
"""
from __future__ import annotations

import platform
from pathlib import Path

from pgae_lite.config import Profile
from pgae_lite.data.dataset import PGAEDataset
from pgae_lite.evaluate.table1 import evaluate
from pgae_lite.runs.data import data_source, loaded
from pgae_lite.runs.pipeline import train_when_free, unit_profile
from pgae_lite.runs.rows import Row, Training
from pgae_lite.train.checkpoint import check_fitted_on
from pgae_lite.util.storage import cache_dir

SHARED_WITH_SELF = ("execute", "repeat language")   # no action shown: the opposite view changes nothing
def table1_unit(original_data: str | None, profile: Profile, training: Training, seed: int, rows: list[Row],
                out: str, device: str | None = None, pretrained_model: str | None = None,
                progress: bool = False) -> dict:
    """Train (or resume) ``training`` with ``seed`` into ``out/TRAINING-seedS``, measure its ``rows``.

    Returns ``{"training", "seed", "seconds", "cells": {row: cells}, "predictions": {row: {signal:
    Predictions}}, "profile": the recipe, "normaliser": the statistics it was trained on, "made_on": host
    and cache}``.
    """
    dataset = loaded(data_source(original_data, profile), device)
    prof = unit_profile(profile, training, seed, dataset, pretrained_model)
    trained = train_when_free(dataset, prof, Path(out) / f"{training.name}-seed{seed}", device, progress,
                              training.name)
    cells, predictions, self_results = {}, {}, None
    for row in rows:
        results, preds = evaluate(trained.model, dataset, trained.normaliser, opposite=row.opposite)
        if row.opposite:
            if self_results is None:
                self_results, _ = evaluate(trained.model, dataset, trained.normaliser)
            results |= {s: self_results[s] for s in SHARED_WITH_SELF}
        else:
            self_results = results
        cells[row.name], predictions[row.name] = results, preds
    return {"training": training.name, "seed": seed, "seconds": trained.seconds, "cells": cells,
            "predictions": predictions, "profile": prof.to_dict(), "normaliser": trained.normaliser.state_dict(),
            "made_on": f"{platform.node()}, cache {cache_dir()}"}


def check_made_on(result: dict, dataset: PGAEDataset, folder: Path) -> None:
    """Raise :class:`~pgae_lite.train.checkpoint.DataMismatchError` unless the unit's model was trained
    on ``dataset`` (the caller's): the same statistics of its training samples, on any machine."""
    check_fitted_on(result, dataset, folder, result["made_on"])


__all__ = ["SHARED_WITH_SELF", "check_made_on", "table1_unit"]
