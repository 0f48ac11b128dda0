"""The family side by side: PRAE, PVAE, PVAE-BERT(-tuned), PGAE, PGAE-BERT and PTAE on one dataset, as Table 1 does.

    python benchmarks/family.py --data original [--rows PRAE PVAE ...] [--seeds 0 1 2] [--profile book] [--workers 2]
    python benchmarks/family.py --data ours ...

Each (row, seed) is one unit of one sweep, so every row's training time is measured in the
same run, side by side with PGAE's. PRAE, PVAE, PVAE-BERT and PVAE-BERT-tuned are trained by
the one training loop (``pgae_lite.train.loop.train``, their trainings of ``pgae_lite.runs.rows``),
in this run, not kept, and measured configured per task (``pgae_lite.evaluate.table1.evaluate``):
a cell their configuration cannot produce is N.A. (``null``). PGAE, PGAE-BERT and PTAE are
trained as units of Table 1 (``pgae_lite.runs.table1_unit``), their models kept in ``--models``
for later experiments.
Writes results/family-original.json or results/family-ours.json: every seed's cells, each
cell's median with the worst and best seed, the training time and the parameter count per row.
"""
from __future__ import annotations

import statistics
from typing import TYPE_CHECKING

from harness import Benchmark, side_by_side

if TYPE_CHECKING:
    from pgae_lite.config import Profile

CELLS = ("accuracy", "nrmse")
CONFIGURED = ("PRAE", "PVAE", "PVAE-BERT", "PVAE-BERT-tuned")   # trained here, not kept; measured per configuration
TRAINED_AS_PGAE = ("PGAE", "PGAE-BERT", "PTAE")      # Table 1's trainings
ROWS = (*CONFIGURED, *TRAINED_AS_PGAE)


def run(row: str, seed: int, profile: Profile, original_data: str | None, models: str) -> dict:
    import torch

    from pgae_lite.config import get_profile
    from pgae_lite.evaluate.table1 import evaluate
    from pgae_lite.model.build import build_model
    from pgae_lite.model.pgae import count_parameters
    from pgae_lite.runs.data import worker_dataset
    from pgae_lite.runs.pipeline import unit_profile
    from pgae_lite.runs.rows import ROWS as BOOK_ROWS
    from pgae_lite.runs.table1_unit import table1_unit
    from pgae_lite.train.loop import train

    torch.set_num_threads(1)                  # one core per worker
    profile = get_profile(profile, seed=seed)
    data = worker_dataset(original_data, profile, "cpu")
    training = BOOK_ROWS[row].training
    if row in CONFIGURED:
        prof = training.profile(profile, samples=len(data.split("train")))
        trained = train(data, prof, device="cpu", progress=False, name=row)
        cells, _ = evaluate(trained.model, data, trained.normaliser)
        seconds, parameters = trained.seconds, count_parameters(trained.model)
    else:
        unit = table1_unit(original_data, profile, training, seed, [BOOK_ROWS[row]], models, "cpu")
        cells, seconds = unit["cells"][row], unit["seconds"]
        parameters = count_parameters(build_model(unit_profile(profile, training, seed, data).model))
    cells = {s: {k: c[k] for k in ("accuracy", "nrmse", "n")} for s, c in cells.items()}
    return {"row": row, "seed": seed, "train_seconds": round(seconds, 1), "parameters": parameters, "cells": cells}


def summary(runs: list[dict]) -> dict:
    """Per row: each cell's median, worst and best seed (None where N.A.), time and parameters."""
    out = {}
    for name in dict.fromkeys(r["row"] for r in runs):
        mine = [r for r in runs if r["row"] == name]
        stats = {}
        for signal in mine[0]["cells"]:
            stats[signal] = {}
            for cell in CELLS:
                values = [r["cells"][signal][cell] for r in mine]
                stats[signal][cell] = None if values[0] is None else {
                    "median": statistics.median(values), "min": min(values), "max": max(values)}
        out[name] = {"stats": stats, "train_seconds": [r["train_seconds"] for r in mine],
                     "parameters": mine[0]["parameters"]}
    return out


def main() -> None:
    bench = Benchmark("family", __doc__, seeds=[0, 1, 2])
    bench.add_original_data()
    bench.parser.add_argument("--data", choices=["original", "ours"], default="original",
                              help="the authors' data (--original-data) or ours, the profile's simulated data")
    bench.parser.add_argument("--rows", nargs="+", default=list(ROWS), choices=ROWS)
    bench.parser.add_argument("--models", default="runs/family", metavar="DIR",
                              help="where PGAE, PGAE-BERT and PTAE are trained (resumed if there), "
                                   "a folder per data (default: runs/family)")
    bench.add_workers(2, "trainings")
    args = bench.parse()
    bench.name = f"family-{args.data}"
    original = args.original_data if args.data == "original" else None
    models = f"{args.models}/{args.data}-{args.profile}"
    from pgae_lite.config import get_profile
    profile = get_profile(args.profile)                  # resolved once, here
    jobs = [(row, seed, profile, original, models) for row in args.rows for seed in args.seeds]
    runs = side_by_side(run, jobs, args.workers)
    table = summary(runs)
    for name, row in table.items():
        shown = {s: tuple("N.A." if c[k] is None else round(c[k]["median"], 3) for k in CELLS)
                 for s, c in row["stats"].items()}
        print(name, shown, f"{statistics.median(row['train_seconds']):.0f} s", row["parameters"], "parameters")
    bench.write({"data": args.data, "rows": table, "runs": runs})


if __name__ == "__main__":
    main()
