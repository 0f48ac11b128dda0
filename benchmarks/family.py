"""The family side by side, first rows: PRAE and PVAE on the authors' data, as Table 1 measures PGAE.

    python benchmarks/family.py [--models PRAE PVAE] [--seeds 0 1 2] [--profile book] [--workers 2]

Each (model, seed) is one unit of a sweep: the model trained with the profile's recipe
(``pgae_lite.family.train.train_family``) on the authors' training split and measured on the
test split configured per task (``pgae_lite.family.configured.evaluate_configured``), so every
cell its configuration cannot produce is N.A. (``null``). Writes results/family-original.json:
every seed's cells, each cell's median with the worst and best seed, the training time and
the parameter count per model.
"""
from __future__ import annotations

import statistics

import torch

from harness import Benchmark, side_by_side

CELLS = ("accuracy", "nrmse")


def run(name: str, seed: int, profile_name: str, path: str) -> dict:
    from pgae_lite.config import get_profile
    from pgae_lite.data.original import load_original
    from pgae_lite.family.configured import evaluate_configured
    from pgae_lite.family.train import train_family
    from pgae_lite.model.pgae import count_parameters

    torch.set_num_threads(1)                  # one core per worker
    profile = get_profile(profile_name, seed=seed)
    data = load_original(path)
    trained = train_family(name, data, profile.model, profile.train, device="cpu")
    cells, _ = evaluate_configured(trained.model, data, trained.normaliser)
    return {"model": name, "seed": seed, "train_seconds": round(trained.seconds, 1),
            "parameters": count_parameters(trained.model), "cells": cells}


def summary(runs: list[dict]) -> dict:
    """Per model: each cell's median, worst and best seed (None where N.A.), time and parameters."""
    out = {}
    for name in dict.fromkeys(r["model"] for r in runs):
        mine = [r for r in runs if r["model"] == name]
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
    bench = Benchmark("family-original", __doc__, seeds=[0, 1, 2])
    bench.add_original_data()
    bench.parser.add_argument("--models", nargs="+", default=["PRAE", "PVAE"], choices=["PRAE", "PVAE"])
    bench.add_workers(2, "trainings")
    args = bench.parse()
    jobs = [(name, seed, args.profile, args.original_data) for name in args.models for seed in args.seeds]
    runs = side_by_side(run, jobs, args.workers)
    table = summary(runs)
    for name, row in table.items():
        shown = {s: c["accuracy"]["median"] if c["accuracy"] else round(c["nrmse"]["median"], 3)
                 for s, c in row["stats"].items()}
        print(name, shown, f"{statistics.median(row['train_seconds']):.0f} s", row["parameters"], "parameters")
    bench.write({"data": "original", "models": table, "runs": runs})


if __name__ == "__main__":
    main()
