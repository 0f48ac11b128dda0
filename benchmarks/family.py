"""The family side by side: PRAE, PVAE, PVAE-BERT(-tuned), PGAE, PGAE-BERT and PTAE on one dataset, as Table 1 does.

    python benchmarks/family.py --data original [--rows PRAE PVAE ...] [--seeds 0 1 2] [--profile book] [--workers 2]
    python benchmarks/family.py --data ours ...

Each (row, seed) is one unit of one sweep, so every row's training time is measured in the
same run, side by side with PGAE's. PRAE, PVAE, PVAE-BERT and PVAE-BERT-tuned are trained by
``pgae_lite.family.train.train_family`` and measured configured per task
(``pgae_lite.family.configured.evaluate_configured``): a cell their configuration cannot
produce is N.A. (``null``). PGAE, PGAE-BERT and PTAE are Table 1's trainings
(``pgae_lite.runs.table1_unit``), their models kept in ``--models`` for later experiments.
Writes results/family-original.json or results/family-ours.json: every seed's cells, each
cell's median with the worst and best seed, the training time and the parameter count per row.
"""
from __future__ import annotations

import statistics

from harness import Benchmark, side_by_side

CELLS = ("accuracy", "nrmse")
CONFIGURED = ("PRAE", "PVAE", "PVAE-BERT", "PVAE-BERT-tuned")   # trained by family.train, measured per configuration
TRAINED_AS_PGAE = ("PGAE", "PGAE-BERT", "PTAE")      # Table 1's trainings
ROWS = (*CONFIGURED, *TRAINED_AS_PGAE)


def run(row: str, seed: int, profile_name: str, original_data: str | None, models: str) -> dict:
    import torch

    from pgae_lite.bert.encoders import build_pgae
    from pgae_lite.config import get_profile
    from pgae_lite.family.configured import evaluate_configured
    from pgae_lite.family.train import family_recipe, train_family
    from pgae_lite.model.pgae import count_parameters
    from pgae_lite.runs.table1_unit import table1_unit, unit_profile, worker_dataset

    torch.set_num_threads(1)                  # one core per worker
    profile = get_profile(profile_name, seed=seed)
    data = worker_dataset(original_data, profile, "cpu")
    if row in CONFIGURED:
        recipe = family_recipe(row, profile.train, profile.name, len(data.split("train")))
        trained = train_family(row, data, profile.model, recipe, device="cpu")
        cells, _ = evaluate_configured(trained.model, data, trained.normaliser)
        seconds, parameters = trained.seconds, count_parameters(trained.model)
    else:
        unit = table1_unit(original_data, profile, row, seed, [row], models, "cpu")
        cells, seconds = unit["cells"][row], unit["seconds"]
        parameters = count_parameters(build_pgae(unit_profile(profile, row, seed).model))
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
    jobs = [(row, seed, args.profile, original, models) for row in args.rows for seed in args.seeds]
    runs = side_by_side(run, jobs, args.workers)
    table = summary(runs)
    for name, row in table.items():
        shown = {s: tuple("N.A." if c[k] is None else round(c[k]["median"], 3) for k in CELLS)
                 for s, c in row["stats"].items()}
        print(name, shown, f"{statistics.median(row['train_seconds']):.0f} s", row["parameters"], "parameters")
    bench.write({"data": args.data, "rows": table, "runs": runs})


if __name__ == "__main__":
    main()
