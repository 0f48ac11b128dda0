"""Incongruent input: which modality PGAE and PTAE follow when the action and the description disagree.

    python benchmarks/incongruent.py [--models-of PGAE PTAE] [--seeds 0 1 2] [--models runs/family]

Loads the models ``benchmarks/family.py`` trained on the authors' data into ``--models`` (or
trains them there, with the same recipe and seeds) and runs both experiments of
``pgae_lite.evaluate.incongruent`` on the test split: language conflicts (describe, one word of the
description swapped) and action conflicts (execute, another pattern's recording shown).
Writes results/incongruent.json: every model's and seed's cells, and their medians.
"""
from __future__ import annotations

import statistics
from pathlib import Path
from typing import TYPE_CHECKING

from harness import Benchmark, side_by_side

if TYPE_CHECKING:
    from pgae_lite.config import Profile


def run(model: str, seed: int, profile: Profile, original: str, models: str) -> dict:
    import torch

    from pgae_lite.config import get_profile
    from pgae_lite.evaluate.incongruent import incongruent_cells
    from pgae_lite.runs.data import worker_dataset
    from pgae_lite.runs.pipeline import train_when_free, unit_profile
    from pgae_lite.runs.rows import TRAININGS

    torch.set_num_threads(1)
    profile = get_profile(profile, seed=seed)
    data = worker_dataset(original, profile, "cpu")
    prof = unit_profile(profile, TRAININGS[model], seed, data)
    trained = train_when_free(data, prof, Path(models) / f"{model}-seed{seed}", "cpu", False, model)
    return {"model": model, "seed": seed, "cells": incongruent_cells(trained.model, data, trained.normaliser, seed)}


def medians(runs: list[dict]) -> dict:
    """Per model, per experiment and conflict, the median of every measure over the seeds."""
    out = {}
    for model in dict.fromkeys(r["model"] for r in runs):
        mine = [r["cells"] for r in runs if r["model"] == model]
        out[model] = {exp: {kind: {m: statistics.median(c[exp][kind][m] for c in mine) for m in cells}
                            for kind, cells in mine[0][exp].items()}
                      for exp in ("language", "action")}
    return out


def main() -> None:
    bench = Benchmark("incongruent", __doc__, seeds=[0, 1, 2])
    bench.add_original_data()
    bench.parser.add_argument("--models-of", nargs="+", default=["PGAE", "PTAE"], choices=["PGAE", "PTAE"])
    bench.parser.add_argument("--models", default="runs/family", metavar="DIR",
                              help="where benchmarks/family.py trained the models (default: runs/family)")
    bench.add_workers(2, "models")
    args = bench.parse()
    models = f"{args.models}/original-{args.profile}"
    runs = side_by_side(run, [(m, s, args.profile, args.original_data, models)
                              for m in args.models_of for s in args.seeds], args.workers)
    table = medians(runs)
    for model, cells in table.items():
        print(model, "language:", {k: round(v["described right"], 1) for k, v in cells["language"].items()},
              "action:", {k: round(v["nrmse to the described"], 2) for k, v in cells["action"].items()})
    bench.write({"data": "original", "medians": table, "runs": runs})


if __name__ == "__main__":
    main()
