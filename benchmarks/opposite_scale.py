"""Chapter 06's question: why does the paper's PGAE-opposite describe 65.28% and ours about all?

    python benchmarks/opposite_scale.py [--data ours original] [--scalings whiten whiten-per-view global]
                                        [--seeds 0 1 2] [--workers 2] [--threads 1]

The two-view model (``PGAE-views``: the recipe with ``opposite_prob = 0.5``) is trained
with three scalings of the visual features, on each dataset, once per seed:

- ``whiten``: the recipe's; both views whitened with one transform, then NICO's view's
  minimum and maximum for both (one picture, one set of numbers);
- ``whiten-per-view``: the same, but each view scaled by its own minimum and maximum, as
  the recipe did before the one-scale fix;
- ``global``: the authors' code's scaling, no whitening, each view its own minimum and maximum.

With ``--curve 10 20 40 ...`` it instead trains the recipe's two-view model once per seed and
dataset, afresh, and describes the test split from both views at those epochs of the training:
how the gap between the views closes as the model learns (results/opposite_scale-curve.json).

Each model is evaluated on the test split on both views (PGAE-self and PGAE-opposite);
beside the cells, how much of [-1, 1] the other agent's motion covers after scaling
(``opposite_spread``, :func:`pgae_lite.data.normaliser.spread_of`). Our data's models are cached
as every training is; the authors' data's runs resume under benchmarks/out/. Writes
results/opposite_scale-ours.json or opposite_scale-original.json (one dataset asked for),
else results/opposite_scale.json.
"""
from __future__ import annotations

from pathlib import Path

import torch
from harness import Benchmark, side_by_side

from pgae_lite.config import Profile, get_profile
from pgae_lite.data.normaliser import Normaliser, spread_of
from pgae_lite.data.original import load_original
from pgae_lite.evaluate.table1 import evaluate, predict
from pgae_lite.runs.data import simulated_dataset
from pgae_lite.runs.pipeline import trained_model, unit_profile
from pgae_lite.runs.rows import TRAININGS, Training
from pgae_lite.train.loop import train

VIEWS = TRAININGS["PGAE-views"]


def views_with(scaling: str) -> Training:
    """PGAE-views with the visual features scaled by ``scaling`` (the recipe's itself for "whiten")."""
    if scaling == "whiten":
        return VIEWS
    return Training(f"PGAE-views-{scaling}", train={**VIEWS.train, "vision_scaling": scaling})


def run(source: str, scaling: str, seed: int, profile: Profile, path: str) -> dict:
    torch.set_num_threads(1)                  # one core per worker
    chosen = views_with(scaling)
    if source == "ours":
        data = simulated_dataset(profile, "cpu", progress=False)
        trained = trained_model(chosen, profile, seed, device="cpu", progress=False)
    else:
        data = load_original(path)
        prof = unit_profile(profile, chosen, seed, data)
        out = Path("benchmarks/out") / f"opposite_scale-{profile.name}-{chosen.name}-s{seed}"
        trained = train(data, prof, out_dir=out, progress=False)
    cells = {}
    for view, opposite in (("self", False), ("opposite", True)):
        result, _ = evaluate(trained.model, data, trained.normaliser, opposite=opposite)
        cells[view] = {s: {k: round(v, 4) for k, v in c.items()} for s, c in result.items()}
    row = {"data": source, "scaling": scaling, "seed": seed, "train_seconds": round(trained.seconds, 1),
           "opposite_spread": round(spread_of(data, scaling), 4), "table1": cells}
    print({k: v for k, v in row.items() if k != "table1"},
          {v: cells[v]["describe"]["accuracy"] for v in cells}, flush=True)
    return row


def curve(source: str, seed: int, profile: Profile, path: str, epochs: list[int]) -> dict:
    """One training of the recipe's two-view model; describe on both views at ``epochs``."""
    torch.set_num_threads(1)
    data = simulated_dataset(profile, "cpu", progress=False) if source == "ours" else load_original(path)
    profile = unit_profile(profile, VIEWS, seed, data)
    normaliser = Normaliser.fit(data.split("train"), profile.train.vision_scaling)   # the training's own
    test = data.split("test")
    points = []

    def describe(epoch: int, model, record: dict) -> None:
        if epoch in epochs:
            points.append({"epoch": epoch, **{view: round(100 * float(predict(
                model, test, normaliser, "describe", opposite=opposite).correct.mean()), 2)
                for view, opposite in (("self", False), ("opposite", True))}})

    train(data, profile, progress=False, callback=describe)
    print(source, seed, points, flush=True)
    return {"data": source, "seed": seed, "points": points}


def main() -> None:
    bench = Benchmark("opposite_scale", __doc__, seeds=[0, 1, 2])
    bench.add_original_data()
    bench.add_workers(2, "trainings")
    bench.parser.add_argument("--data", nargs="+", default=["ours", "original"], choices=["ours", "original"])
    bench.parser.add_argument("--scalings", nargs="+", default=["whiten", "whiten-per-view", "global"])
    bench.parser.add_argument("--curve", type=int, nargs="+", metavar="EPOCH",
                              help="describe on both views at these epochs of one training per seed")
    args = bench.parse()
    profile = get_profile(args.profile)                          # resolved once, here
    if args.curve:
        bench.name = "opposite_scale-curve"
        if "ours" in args.data:
            simulated_dataset(profile, "cpu", progress=False)
        jobs = [(source, seed, profile, args.original_data, args.curve)
                for source in args.data for seed in args.seeds]
        return bench.write({"training": VIEWS.name, "epochs": args.curve,
                            "runs": side_by_side(curve, jobs, args.workers)})
    if len(args.data) == 1:
        bench.name = f"opposite_scale-{args.data[0]}"
    if "ours" in args.data:
        simulated_dataset(profile, "cpu", progress=False)            # recorded once, before the workers start
    jobs = [(source, scaling, seed, profile, args.original_data)
            for source in args.data for scaling in args.scalings for seed in args.seeds]
    rows = side_by_side(run, jobs, args.workers)
    bench.write({"training": VIEWS.name, "runs": rows})


if __name__ == "__main__":   # spawned workers re-import this file
    main()
