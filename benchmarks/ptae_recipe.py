"""PTAE's book recipe against its paper's settings, one change at a time, on the authors' data.

    python benchmarks/ptae_recipe.py [--seeds 0] [--workers 2]

Each variant is the book's PTAE (``pgae_lite.runs.rows.TRAININGS["PTAE"]``: width 128, feed-forward 512, no
dropout, positions on the frames) with some of PTAE's own settings put back (width 256,
feed-forward 1024, dropout 0.25, frames without positions), trained with the book's recipe and
measured as Table 1 measures PGAE. One unit of one sweep per (variant, seed), so the times
compare. Writes results/ptae_recipe.json.
"""
from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING

from harness import Benchmark, side_by_side

if TYPE_CHECKING:
    from pgae_lite.config import Profile
    from pgae_lite.model.config import ModelConfig

#: variant -> what it changes in the book's PTAE (the width in the model, the rest in its crossmodal part)
VARIANTS = {
    "book": {},
    "dropout 0.25": {"dropout": 0.25},
    "frames without positions": {"frame_positions": False},
    "width 256, feed-forward 1024": {"hidden": 256, "feedforward": 1024},
    "PTAE's own (all four)": {"hidden": 256, "feedforward": 1024, "dropout": 0.25, "frame_positions": False},
}


def with_changes(model: "ModelConfig", changes: dict) -> "ModelConfig":
    """PTAE's ``model`` with a variant's ``changes``: ``hidden`` the model's, the others its crossmodal part's."""
    crossmodal = {k: v for k, v in changes.items() if k != "hidden"}
    width = {k: v for k, v in changes.items() if k == "hidden"}
    return replace(model, **width, crossmodal=replace(model.crossmodal, **crossmodal))


def run(variant: str, seed: int, profile: Profile, original: str) -> dict:
    import torch

    from pgae_lite.config import get_profile
    from pgae_lite.evaluate.table1 import evaluate
    from pgae_lite.model.pgae import count_parameters
    from pgae_lite.runs.data import worker_dataset
    from pgae_lite.runs.rows import TRAININGS
    from pgae_lite.train.loop import train

    torch.set_num_threads(1)
    profile = get_profile(profile, seed=seed)
    prof = TRAININGS["PTAE"].profile(profile)
    prof = replace(prof, model=with_changes(prof.model, VARIANTS[variant]))
    data = worker_dataset(original, profile, "cpu")
    trained = train(data, prof, device="cpu", progress=False, name="PTAE")
    cells, _ = evaluate(trained.model, data, trained.normaliser)
    return {"variant": variant, "changes": VARIANTS[variant], "seed": seed, "train_seconds": round(trained.seconds, 1),
            "parameters": count_parameters(trained.model),
            "cells": {s: {"accuracy": c["accuracy"], "nrmse": c["nrmse"]} for s, c in cells.items()}}


def main() -> None:
    bench = Benchmark("ptae_recipe", __doc__, seeds=[0])
    bench.add_original_data()
    bench.add_workers(2, "trainings")
    args = bench.parse()
    from pgae_lite.config import get_profile
    profile = get_profile(args.profile)                  # resolved once, here
    runs = side_by_side(run, [(v, s, profile, args.original_data) for v in VARIANTS for s in args.seeds],
                        args.workers)
    for r in runs:
        print(f"{r['variant']:30s} seed {r['seed']}: " + ", ".join(
            f"{s} {c['accuracy']:.1f}% / {c['nrmse']:.3f}%" for s, c in r["cells"].items())
            + f"; {r['train_seconds']:.0f} s")
    bench.write({"data": "original", "variants": VARIANTS, "runs": runs})


if __name__ == "__main__":
    main()
