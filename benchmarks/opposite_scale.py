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

Each model is evaluated on the test split on both views (PGAE-self and PGAE-opposite);
beside the cells, how much of [-1, 1] the other agent's motion covers after scaling
(``opposite_spread``: the std of the opposite view's features over the valid training steps,
divided by that of NICO's view, averaged over the 30 features). Our data's models are cached
as every training is; the authors' data's runs resume under benchmarks/out/. Writes
results/opposite_scale.json.
"""
from __future__ import annotations

from pathlib import Path

import torch

from harness import Benchmark, side_by_side
from pgae_lite.config import TRAININGS, Training, get_profile, training_profile
from pgae_lite.data.dataset import Normaliser
from pgae_lite.data.original import load_original
from pgae_lite.evaluate import evaluate
from pgae_lite.runs.pipeline import simulated_dataset, trained_pgae
from pgae_lite.train.loop import train

VIEWS = TRAININGS["PGAE-views"]


def views_with(scaling: str) -> Training:
    """PGAE-views with the visual features scaled by ``scaling`` (the recipe's itself for "whiten")."""
    if scaling == "whiten":
        return VIEWS
    return Training(f"PGAE-views-{scaling}", train={**VIEWS.train, "vision_scaling": scaling})


def spread(data, scaling: str) -> float:
    """The opposite view's std after scaling over NICO's view's, feature by feature, averaged."""
    train_set = data.split("train")
    t = Normaliser.fit(train_set, scaling).tensors(train_set)
    valid = torch.from_numpy(train_set.mask)
    mine, theirs = t["vision"][valid].std(0), t["vision_opposite"][valid].std(0)      # (30,) each
    return float((theirs / mine).mean())


def run(source: str, scaling: str, seed: int, profile_name: str, path: str) -> dict:
    torch.set_num_threads(1)                  # one core per worker
    chosen = views_with(scaling)
    if source == "ours":
        data = simulated_dataset(profile_name, "cpu", progress=False)
        trained = trained_pgae(chosen, profile_name, seed, device="cpu", progress=False)
    else:
        data = load_original(path)
        profile = training_profile(get_profile(profile_name, seed=seed), chosen)
        out = Path("benchmarks/out") / f"opposite_scale-{profile_name}-{chosen.name}-s{seed}"
        trained = train(data, profile, out_dir=out, progress=False)
    cells = {}
    for view, opposite in (("self", False), ("opposite", True)):
        result, _ = evaluate(trained.model, data, trained.normaliser, opposite=opposite)
        cells[view] = {s: {k: round(v, 4) for k, v in c.items()} for s, c in result.items()}
    row = {"data": source, "scaling": scaling, "seed": seed, "train_seconds": round(trained.seconds, 1),
           "opposite_spread": round(spread(data, scaling), 4), "table1": cells}
    print({k: v for k, v in row.items() if k != "table1"},
          {v: cells[v]["describe"]["accuracy"] for v in cells}, flush=True)
    return row


def main() -> None:
    bench = Benchmark("opposite_scale", __doc__, seeds=[0, 1, 2])
    bench.add_original_data()
    bench.add_workers(2, "trainings")
    bench.parser.add_argument("--data", nargs="+", default=["ours", "original"], choices=["ours", "original"])
    bench.parser.add_argument("--scalings", nargs="+", default=["whiten", "whiten-per-view", "global"])
    args = bench.parse()
    if "ours" in args.data:
        simulated_dataset(args.profile, "cpu", progress=False)       # recorded once, before the workers start
    jobs = [(source, scaling, seed, args.profile, args.original_data)
            for source in args.data for scaling in args.scalings for seed in args.seeds]
    rows = side_by_side(run, jobs, args.workers)
    bench.write({"training": VIEWS.name, "runs": rows})


if __name__ == "__main__":   # spawned workers re-import this file
    main()
