"""Teach NICO a new colour, end to end: record, retrain the CAE and PGAE, check.

Runs every step of the book's guided project (appendix A3) once and times it, through the one
pipeline (pgae_lite.runs.pipeline) on the profile in the new world (pgae_lite.config.with_world):
the new episodes (pgae_lite.sim.dataset.generate of the world's own recordings,
DatasetConfig.parts()), the CAE on old + new frames, the features of every episode, PGAE built
for the enlarged vocabulary, and pgae_lite.exercises.check_new_colour on the held-out episodes. It also writes
Table 1's cells on the paper's 36 test patterns and on the new ones, and the
reference errors the check's execute threshold is argued from (what following
the wrong cube's or the wrong action's mean trajectory costs).

    python benchmarks/new_colour.py --threads 1                 # the book profile
    python benchmarks/new_colour.py --threads 1 --epochs 100    # a reduced budget

Every step is cached (PGAE_LITE_CACHE): a second run only evaluates; the result
says which steps came from the cache (their seconds are then loading times).
"""
from __future__ import annotations

import time

import numpy as np
from harness import Benchmark

from pgae_lite.world.colours import with_colour


def reference_errors(data) -> dict:
    """nRMSE (%) of each test episode against the mean training trajectory of the same
    action, of the same action on the other cube, and of the nearest other action."""
    scale = data.joint_range()
    train = ~data.is_test
    mean = {c: data.joints[(data.action == c) & train].mean(0)
            for c in set(data.action)}                      # action code -> (100, 5)

    def err(i: int, code: str) -> float:
        m = data.mask[i]
        mse = ((data.joints[i] - mean[code]) ** 2)[m].mean()
        return 100 * float(np.sqrt(mse)) / scale
    same, other_cube, other_action = [], [], []
    for i in np.flatnonzero(data.is_test):
        act, side, speed = str(data.action[i]).split("-")
        same.append(err(i, data.action[i]))
        other_cube.append(err(i, f"{act}-{'R' if side == 'L' else 'L'}-{speed}"))
        others = [a for a in ("PUSH", "PULL", "SLIDE") if a != act]
        other_action.append(min(err(i, f"{a}-{side}-{speed}") for a in others))
    summary = {}
    for name, values in (("same_action", same), ("other_cube", other_cube),
                         ("other_action", other_action)):
        summary[name] = {"median": round(float(np.median(values)), 3),
                         "min": round(float(np.min(values)), 3),
                         "max": round(float(np.max(values)), 3)}
    return summary


def main() -> None:
    bench = Benchmark("new_colour", __doc__)
    bench.parser.add_argument("--colour", default="orange")
    bench.parser.add_argument("--synonym", default="amber")
    bench.parser.add_argument("--rgba", type=float, nargs=4,
                              default=(0.98, 0.50, 0.05, 1.0))
    bench.parser.add_argument("--epochs", type=int, default=None,
                              help="PGAE epochs (default: the profile's)")
    args = bench.parse()

    import torch

    from pgae_lite.config import get_profile, with_world
    from pgae_lite.evaluate.table1 import evaluate
    from pgae_lite.exercises import check_new_colour
    from pgae_lite.runs import data as data_pipeline
    from pgae_lite.runs import pipeline
    from pgae_lite.runs.rows import TRAININGS
    from pgae_lite.sim.dataset import generate

    world = with_colour(args.colour, args.synonym, args.rgba)
    overrides = {"epochs": args.epochs} if args.epochs else {}
    coloured = with_world(get_profile(args.profile, **overrides), world)     # resolved once, here
    seed, training = args.seeds[0], TRAININGS["PGAE"]
    cae = data_pipeline.cae_path(coloured.data, coloured.cae)
    # PGAE's recipe with the seed (unit_profile's, without the data: PGAE's authors count no iterations)
    folder = pipeline.model_folder(training.profile(get_profile(coloured, seed=seed)), training.name)
    cached = {"cae": cae.exists(),                      # True: the step only loads
              "features": (cae.parent.parent / "features" / f"{cae.stem}.npz").exists(),
              "pgae": (folder / "checkpoint.pt").exists()}
    seconds, t = {}, time.perf_counter()
    # the world's own episodes (the last of its parts); the paper's come from the profile's cache
    report = generate(coloured.data.parts()[-1], progress=False)
    seconds["record"] = round(time.perf_counter() - t, 1)
    t = time.perf_counter()
    data_pipeline.trained_cae(coloured, progress=False)
    seconds["cae"] = round(time.perf_counter() - t, 1)
    t = time.perf_counter()
    data = data_pipeline.simulated_dataset(coloured, progress=False)
    seconds["features"] = round(time.perf_counter() - t, 1)
    t = time.perf_counter()
    trained = pipeline.trained_model(training, coloured, seed, progress=False)
    seconds["pgae"] = round(time.perf_counter() - t, 1)
    t = time.perf_counter()
    check = check_new_colour(trained.model, trained.normaliser, data, args.colour)
    seconds["check"] = round(time.perf_counter() - t, 1)
    print(check)

    new = np.isin(data.pattern, world.new_patterns)
    cells = {}
    for name, subset in (("paper_patterns", data.subset(~new)),
                         ("new_patterns", data.subset(new))):
        res, _ = evaluate(trained.model, subset, trained.normaliser,
                          joint_range=data.joint_range())
        cells[name] = {s: {k: round(v, 3) for k, v in c.items()}
                       for s, c in res.items()}
    bench.write({
        "world": {"colour": args.colour, "synonym": args.synonym,
                  "rgba": list(args.rgba),
                  "arrangements": [list(a) for a in world.arrangements[12:]],
                  "new_patterns": len(world.new_patterns),
                  "new_test_patterns": sorted(p for p in world.test_patterns
                                              if p >= 144),
                  "vocabulary": len(world.lexicon.vocabulary)},
        "samples": {"all": len(data), "train": int((~data.is_test).sum()),
                    "test": int(data.is_test.sum()), "new": int(new.sum())},
        "episodes_recorded": report.recorded, "first_try": round(report.first_try, 3),
        "epochs": trained.profile.train.epochs,
        "cae_iterations": trained.profile.cae.iterations,
        "seconds_per_step": seconds, "from_cache": cached,
        "train_seconds": round(trained.seconds, 1),
        "threads": torch.get_num_threads(),
        "check": {"passed": bool(check), "lines": check.lines},
        "cells": cells, "reference_nrmse": reference_errors(data)})


if __name__ == "__main__":
    main()
