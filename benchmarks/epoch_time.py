"""Seconds per training epoch of the recipe and of candidate changes to it, timed in one run.

    python benchmarks/epoch_time.py --candidates time_stride=3 units=80,time_stride=3 batch_size=24
                                    [--original-data PATH] [--epochs 3] [--rounds 2] [--threads 1]

On the authors' data (648 training samples), with the real training loop
(:func:`pgae_lite.train.loop.train`). A candidate is one or more options of the
recipe's model (:class:`~pgae_lite.model.config.ModelConfig`) or training
(:class:`~pgae_lite.train.config.TrainConfig`), ``KEY=VALUE`` joined by commas (plain
values: not a recipe's parts, such as ``language`` or ``supervision``). Each
setting trains ``--epochs`` epochs (the first, a warm-up, is not counted); the
settings take turns, ``--rounds`` times over, so that a slow spell of a
shared machine falls on all of them. Reports each setting's fastest epoch and
its ratio to the recipe's: what a candidate would save in time, before anyone
trains it in full to see what it costs in quality. Writes results/epoch_time.json.
Run it on an otherwise idle machine.
"""
from __future__ import annotations

import argparse
import time
from dataclasses import fields, replace

from harness import Benchmark, key_value

from pgae_lite.config import Profile, get_profile
from pgae_lite.data.original import load_original
from pgae_lite.model.config import PARTS, ModelConfig
from pgae_lite.train.config import TRAIN_PARTS, TrainConfig
from pgae_lite.train.loop import train

MODEL_OPTIONS = {f.name for f in fields(ModelConfig)} - set(PARTS)
TRAIN_OPTIONS = {f.name for f in fields(TrainConfig)} - {"epochs", "seed", "max_train_samples", *TRAIN_PARTS}


def candidate(text: str) -> dict:
    """``KEY=VALUE[,KEY=VALUE...]``: options of ModelConfig or TrainConfig (values JSON where they parse)."""
    changes = dict(key_value(part) for part in text.split(","))
    unknown = sorted(set(changes) - (MODEL_OPTIONS | TRAIN_OPTIONS))
    if unknown:
        raise argparse.ArgumentTypeError(
            f"unknown option(s) {', '.join(unknown)} in {text!r}; the options are: "
            f"{', '.join(sorted(MODEL_OPTIONS | TRAIN_OPTIONS))}")
    return changes


def epoch_seconds(dataset, profile: Profile, changes: dict, epochs: int) -> list[float]:
    """The seconds of each epoch after the first of a training with ``changes`` to the recipe."""
    prof = get_profile(profile, epochs=epochs, **{k: v for k, v in changes.items() if k in TRAIN_OPTIONS})
    prof = replace(prof, model=replace(prof.model, **{k: v for k, v in changes.items() if k in MODEL_OPTIONS}))
    marks = [time.perf_counter()]
    train(dataset, prof, progress=False, callback=lambda *_: marks.append(time.perf_counter()))
    return [b - a for a, b in zip(marks[1:], marks[2:])]     # the first epoch warms up


def main() -> None:
    bench = Benchmark("epoch_time", __doc__)
    bench.add_original_data()
    bench.parser.add_argument("--candidates", nargs="+", type=candidate, required=True, metavar="KEY=VALUE[,...]")
    bench.parser.add_argument("--epochs", type=int, default=3, help="epochs per training, the first not counted")
    bench.parser.add_argument("--rounds", type=int, default=2, help="times every setting is trained, in turn")
    args = bench.parse()
    if args.epochs < 2 or args.rounds < 1:
        bench.parser.error("--epochs must be at least 2 (the first warms up) and --rounds at least 1")
    profile = get_profile(args.profile)                             # resolved once, here
    dataset = load_original(args.original_data)
    settings = [{}] + args.candidates                               # the recipe first
    seconds = [[] for _ in settings]
    for _ in range(args.rounds):
        for times, changes in zip(seconds, settings):
            times += epoch_seconds(dataset, profile, changes, args.epochs)
    recipe = min(seconds[0])
    bench.write({"data": "original", "training_samples": len(dataset.split("train")),
                 "rows": [{"changes": changes, "seconds_per_epoch": round(min(times), 3),
                           "ratio_to_recipe": round(min(times) / recipe, 3), "epochs_timed": len(times)}
                          for changes, times in zip(settings, seconds)]})


if __name__ == "__main__":
    main()
