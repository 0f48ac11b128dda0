"""PVAE-BERT-tuned's top-layer learning rate, chosen on the training split of our data, never on a test set.

    python benchmarks/tuned_rate.py [--scales 0.03 0.003] [--seeds 0] [--workers 2]

Trains PVAE-BERT-tuned (its training of ``pgae_lite.runs.rows``, by ``pgae_lite.train.loop.train``) on
the book profile's simulated data with the top layer's rate at each ``--scales`` fraction of the
recipe's (the free-form variant's ``tuned_layer.LR_SCALE`` first), and measures its configured cells
(``pgae_lite.evaluate.table1.evaluate``, N.A. where it has no path) on the *training* split: a rate at
which the tuned layer forgets what the words say shows there as well, without looking at any test
sample. Writes results/tuned_rate.json.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from harness import Benchmark, side_by_side

if TYPE_CHECKING:
    from pgae_lite.config import Profile


def run(scale: float, seed: int, profile: Profile) -> dict:
    import torch

    from pgae_lite.bert import tuned_encoder
    from pgae_lite.config import get_profile
    from pgae_lite.evaluate.table1 import evaluate
    from pgae_lite.runs.data import worker_dataset
    from pgae_lite.runs.rows import TRAININGS
    from pgae_lite.train.loop import train

    torch.set_num_threads(1)                  # one core per worker
    tuned_encoder.TUNED_LR_SCALE = scale      # read when the encoder is built
    profile = get_profile(profile, seed=seed)
    data = worker_dataset(None, profile, "cpu")
    prof = TRAININGS["PVAE-BERT-tuned"].profile(profile, samples=len(data.split("train")))
    trained = train(data, prof, device="cpu", progress=False, name="PVAE-BERT-tuned")
    cells, _ = evaluate(trained.model, data, trained.normaliser, split="train")
    return {"scale": scale, "seed": seed, "train_seconds": round(trained.seconds, 1),
            "training_split": {s: {k: c[k] for k in ("accuracy", "nrmse")} for s, c in cells.items()}}


def main() -> None:
    from pgae_lite.bert.tuned_layer import LR_SCALE

    bench = Benchmark("tuned_rate", __doc__, seeds=[0])
    bench.parser.add_argument("--scales", type=float, nargs="+", default=[LR_SCALE, LR_SCALE / 10])
    bench.add_workers(2, "trainings")
    args = bench.parse()
    from pgae_lite.config import get_profile
    profile = get_profile(args.profile)                  # resolved once, here
    runs = side_by_side(run, [(s, seed, profile) for s in args.scales for seed in args.seeds], args.workers)
    for r in runs:
        cells = r["training_split"]
        print(f"scale {r['scale']:g}, seed {r['seed']}: describe {cells['describe']['accuracy']:.2f}%, repeat "
              f"language {cells['repeat language']['accuracy']:.2f}%, execute {cells['execute']['nrmse']:.3f}%")
    bench.write({"split": "train", "runs": runs})


if __name__ == "__main__":
    main()
