"""Limited supervision: PGAE against PTAE when only a share of the training pairs an action with its description.

    python benchmarks/limited_supervision.py [--models-of PGAE PTAE] [--shares 1 0.2 0.05 0.02]
        [--subset-shares 0.05 0.02] [--seeds 0 1 2] [--workers 2] [--models runs/family]

Each (model, reading, share, seed) is one unit of one sweep. ``--shares``: the share of paired
updates (``TrainConfig.supervision = SupervisionConfig(share)``, the PTAE authors' reading); 1 is
the recipe itself, whose models ``benchmarks/family.py`` trained into the same ``--models`` folder
(loaded, not trained again). ``--subset-shares``: a fixed labelled share of the samples
(``SupervisionConfig(share, of="samples")``, :mod:`pgae_lite.train.supervision`). Every model is
measured as Table 1 measures PGAE, on the authors' test split. Writes results/limited_supervision.json:
every unit's cells and time, and per (model, reading, share) each cell's median with the worst and best seed.
"""
from __future__ import annotations

import statistics
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

from harness import Benchmark, side_by_side

if TYPE_CHECKING:
    from pgae_lite.config import Profile


def training_of(model: str, reading: str, share: float):
    """The Training of ``model`` with ``share`` of its ``reading`` ("updates" or "samples") paired (1: the model's
    own)."""
    from pgae_lite.runs.rows import TRAININGS
    from pgae_lite.train.supervision import SupervisionConfig

    base = TRAININGS[model]
    if share == 1:
        return base
    return replace(base, name=f"{model}-{reading}-{share:g}",
                   train={**base.train, "supervision": SupervisionConfig(share, of=reading)})


def run(model: str, reading: str, share: float, seed: int, profile: Profile, original: str, models: str) -> dict:
    import torch

    from pgae_lite.config import get_profile
    from pgae_lite.evaluate.table1 import evaluate
    from pgae_lite.runs.data import worker_dataset
    from pgae_lite.runs.pipeline import train_when_free, unit_profile

    torch.set_num_threads(1)
    profile = get_profile(profile, seed=seed)
    data = worker_dataset(original, profile, "cpu")
    training = training_of(model, reading, share)
    prof = unit_profile(profile, training, seed, data)
    trained = train_when_free(data, prof, Path(models) / f"{training.name}-seed{seed}", "cpu", False, training.name)
    cells, _ = evaluate(trained.model, data, trained.normaliser)
    return {"model": model, "reading": reading, "share": share, "seed": seed,
            "train_seconds": round(trained.seconds, 1),
            "cells": {s: {"accuracy": c["accuracy"], "nrmse": c["nrmse"]} for s, c in cells.items()}}


def summary(runs: list[dict]) -> list[dict]:
    """Per (model, reading, share): each cell's median, worst and best seed."""
    keys = dict.fromkeys((r["model"], r["reading"], r["share"]) for r in runs)
    out = []
    for model, reading, share in keys:
        mine = [r for r in runs if (r["model"], r["reading"], r["share"]) == (model, reading, share)]
        stats = {s: {k: {"median": statistics.median(v), "min": min(v), "max": max(v)}
                     for k in ("accuracy", "nrmse") for v in [[r["cells"][s][k] for r in mine]]}
                 for s in mine[0]["cells"]}
        out.append({"model": model, "reading": reading, "share": share, "seeds": [r["seed"] for r in mine],
                    "stats": stats})
    return out


def main() -> None:
    bench = Benchmark("limited_supervision", __doc__, seeds=[0, 1, 2])
    bench.add_original_data()
    bench.parser.add_argument("--models-of", nargs="+", default=["PGAE", "PTAE"], choices=["PGAE", "PTAE"])
    bench.parser.add_argument("--shares", type=float, nargs="+", default=[1.0, 0.2, 0.05, 0.02])
    bench.parser.add_argument("--subset-shares", type=float, nargs="*", default=[0.05, 0.02])
    bench.parser.add_argument("--models", default="runs/family", metavar="DIR",
                              help="where the models are trained (resumed if there; default: runs/family)")
    bench.add_workers(2, "trainings")
    args = bench.parse()
    models = f"{args.models}/original-{args.profile}"           # benchmarks/family.py's folder for this data
    settings = [("updates", s) for s in args.shares] + [("samples", s) for s in args.subset_shares]
    from pgae_lite.config import get_profile
    profile = get_profile(args.profile)                  # resolved once, here
    jobs = [(m, reading, share, seed, profile, args.original_data, models)
            for reading, share in settings for m in args.models_of for seed in args.seeds]
    runs = side_by_side(run, jobs, args.workers)
    table = summary(runs)
    for row in table:
        d, e = row["stats"]["describe"]["accuracy"]["median"], row["stats"]["execute"]["nrmse"]["median"]
        print(f"{row['model']:5s} {row['reading']:8s} {row['share']:5g}: describe {d:6.2f} %, execute nRMSE {e:.3f} %")
    bench.write({"data": "original", "table": table, "runs": runs})


if __name__ == "__main__":
    main()
