"""Chapter 04's ablation exercises at the recipe, three seeds: the reference their solutions quote.

    python benchmarks/ablations.py [--ablations concat no-both ...] [--seeds 0 1 2] [--threads 1] [--workers 2]
                                   [--epochs 30 --out results/ablations-short.json]

Each ablation changes one thing of the profile's recipe (``book``), exactly as its
exercise's solution does, and trains PGAE on our simulated data (the
chapter's data) once per seed; the recipe itself (``recipe``, the cached
:func:`pgae_lite.runs.pipeline.trained_model`) is the baseline, on the same seeds.
Writes every model's Table 1 cells and training time to
results/ablations.json, so a solution can say whether its effect exceeds the
spread of the seeds. With ``--workers N`` N models train side by side, each in
its own process on one thread. With ``--epochs E`` the recipe and every change
train for E epochs instead of the profile's (its schedule scaled to them): a
shorter budget shows what a change does to the speed of learning.
"""
from __future__ import annotations

import copy
from dataclasses import replace

import torch
from harness import Benchmark, side_by_side

from pgae_lite.config import Profile, get_profile
from pgae_lite.evaluate.table1 import evaluate
from pgae_lite.model.layers import ConcatBottleneck
from pgae_lite.model.pgae import PGAE
from pgae_lite.runs.data import worker_dataset
from pgae_lite.runs.pipeline import trained_model
from pgae_lite.runs.rows import TRAININGS
from pgae_lite.train.loop import train
from pgae_lite.world import words as language

#: ex-pgae-no-both: the signals without "repeat both" (describe, execute, repeat action, -, repeat language)
NO_BOTH = (3 / 8, 3 / 8, 1 / 8, 0.0, 1 / 8)


def concat_model(profile):
    model = PGAE(profile.model)
    model.gmu = ConcatBottleneck(model.cfg.state_dim, model.cfg.state_dim, model.cfg.hidden)
    return model


def small_embeddings(profile):
    model = PGAE(profile.model)
    with torch.no_grad():       # ex-pgae-embedding: the authors' U(-0.1, 0.1) input weights
        for rnn in (model.language_encoder.rnn, model.language_decoder.rnn):
            rnn.input_weight.uniform_(-0.1, 0.1)
    return model


def peephole(profile):
    profile = copy.deepcopy(profile)
    profile.model.cell = "peephole"
    return profile


#: name -> (profile change, model builder) of each exercise's solution
ABLATIONS = {
    "concat": (None, concat_model),
    "cells": (peephole, None),
    "no-both": (lambda p: replace(p, train=replace(p.train, signal_probs=NO_BOTH)), None),
    "per-batch": (lambda p: replace(p, train=replace(p.train, signals_per_sample=False)), None),
    "embedding": (None, small_embeddings),
    "weights": ("flat word weights", None),
}


def budget(epochs: int | None) -> dict:
    """The training options that set the budget: none (the profile's), or ``epochs``."""
    return {"epochs": epochs} if epochs else {}


def train_ablation(name: str, data, profile: Profile, seed: int, epochs: int | None = None):
    change, build = ABLATIONS[name]
    profile = get_profile(profile, seed=seed, **budget(epochs))
    if callable(change):
        profile = change(profile)
    if build:           # its initial weights the same for the same seed, whatever this process ran before
        torch.manual_seed(seed)
    model = build(profile) if build else None
    saved = dict(language.WORD_WEIGHTS)
    if change == "flat word weights":             # ex-pgae-weights: every word weighs 1
        language.WORD_WEIGHTS.update({w: 1.0 for w in language.WORD_WEIGHTS})
    try:
        return train(data, profile, model=model, progress=False)
    finally:
        language.WORD_WEIGHTS.update(saved)


def dataset(profile: Profile):
    """The simulated data, loaded once per process (every job in a worker reads the same)."""
    return worker_dataset(None, profile, "cpu")


def measure(name: str, seed: int, profile: Profile, threads: int | None, epochs: int | None = None) -> dict:
    """One model (the recipe's or one ablation's) trained on our data and its Table 1 cells."""
    if threads:
        torch.set_num_threads(threads)
    data = dataset(profile)
    trained = (trained_model(TRAININGS["PGAE"], get_profile(profile, **budget(epochs)), seed, device="cpu",
                             progress=False)
               if name == "recipe" else train_ablation(name, data, profile, seed, epochs))
    cells, _ = evaluate(trained.model, data, trained.normaliser)
    print(name, seed, {s: (round(c["accuracy"], 2), round(c["nrmse"], 3)) for s, c in cells.items()},
          flush=True)
    return {"ablation": name, "seed": seed, "train_seconds": round(trained.seconds, 1),
            "table1": {s: {k: round(v, 4) for k, v in c.items()} for s, c in cells.items()}}


def main() -> None:
    bench = Benchmark("ablations", __doc__, seeds=[0, 1, 2])
    bench.parser.add_argument("--ablations", nargs="+", default=list(ABLATIONS), choices=list(ABLATIONS))
    bench.add_workers(1, "trainings")
    bench.parser.add_argument("--epochs", type=int, default=None,
                              help="train the recipe and every change for this many epochs (default: the profile's)")
    args = bench.parse()
    profile = get_profile(args.profile)                         # resolved once, here
    dataset(profile)                                            # recorded once, before the workers start
    threads = 1 if args.workers > 1 else args.threads
    jobs = [(name, seed, profile, threads, args.epochs) for name in ["recipe", *args.ablations]
            for seed in args.seeds]
    bench.write({"data": "ours (simulated)", "epochs": args.epochs or profile.train.epochs,
                 "runs": side_by_side(measure, jobs, args.workers)})


if __name__ == "__main__":   # recording the data spawns workers, which re-import this file
    main()
