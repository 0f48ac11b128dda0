"""Wall time of one training + evaluation: the book recipe against the one it replaced, side by side.

    python benchmarks/recipe_time.py [--original-data PATH] [--threads 2] [--seeds 0]

On the authors' data, one after the other in this one process (the machines
are shared and noisy: both are timed side by side, on the same data, under
the same load): the recipe before this one, :data:`PREVIOUS` (1,200 epochs
of batch 64, one LSTM step per time step), and the ``book`` profile's. Each
is timed from the first epoch to the last cell of Table 1's PGAE row, and its
cells are kept, so the speed-up is read next to what it costs. Writes
results/recipe_time.json.
"""
from __future__ import annotations

import time
from dataclasses import replace

from harness import Benchmark

from pgae_lite.config import get_profile
from pgae_lite.data.original import load_original
from pgae_lite.evaluate.table1 import evaluate
from pgae_lite.train.loop import train

#: The recipe before (1,200 epochs, at f994b81): what it changes in today's book recipe, its training and model
#: (batches of any length, one LSTM step per time step, the paper's GMU, no plan head).
PREVIOUS = {"epochs": 1200, "batch_size": 64, "lr": 2e-3, "action_weight": 2.0, "length_batches": False,
            "plan_weight": 0.0}
PREVIOUS_MODEL = {"time_stride": 1, "gmu_norm": False, "plan_keyframes": 0}

bench = Benchmark("recipe_time", __doc__)
bench.add_original_data()
args = bench.parse()
base = get_profile(args.profile)                 # resolved once, here
dataset = load_original(args.original_data)

rows = []
for seed in args.seeds:
    for name, overrides, model in (("previous", PREVIOUS, PREVIOUS_MODEL), ("book", {}, {})):
        profile = get_profile(base, seed=seed, **overrides)
        profile.model = replace(profile.model, **model)
        t0 = time.perf_counter()
        trained = train(dataset, profile, progress=False)
        train_seconds = time.perf_counter() - t0
        cells, _ = evaluate(trained.model, dataset, trained.normaliser, joint_range=dataset.joint_range())
        seconds = time.perf_counter() - t0
        t = profile.train
        rows.append({"recipe": name, "seed": seed, "epochs": t.epochs, "batch_size": t.batch_size, "lr": t.lr,
                     "action_weight": t.action_weight, "time_stride": profile.model.time_stride,
                     "train_seconds": round(train_seconds, 1), "seconds": round(seconds, 1),
                     "cells": {s: {k: round(v, 4) for k, v in c.items()} for s, c in cells.items()}})
        print(f"seed {seed} {name:8s}: {t.epochs} epochs x batch {t.batch_size}: {seconds / 60:.2f} min "
              f"(training {train_seconds / 60:.2f}); " + ", ".join(
                  f"{s} {c['accuracy']:.2f}% / {c['nrmse']:.3f}%" for s, c in cells.items()))
previous = sum(r["seconds"] for r in rows if r["recipe"] == "previous")
book = sum(r["seconds"] for r in rows if r["recipe"] == "book")
print(f"speed-up: {previous / book:.2f}x")
minutes = {name: round(sum(r["seconds"] for r in rows if r["recipe"] == name) / 60 / len(args.seeds), 2)
           for name in ("previous", "book")}
bench.write({"data": "original", "rows": rows, "minutes": minutes, "speedup": round(previous / book, 2)})
