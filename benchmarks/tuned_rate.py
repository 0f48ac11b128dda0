"""PVAE-BERT-tuned's top-layer learning rate, chosen on the training split of our data, never on a test set.

    python benchmarks/tuned_rate.py [--scales 0.03 0.003] [--seeds 0] [--workers 2]

Trains PVAE-BERT-tuned (``pgae_lite.family.train``) on the book profile's simulated data with the
top layer's rate at each ``--scales`` fraction of the recipe's (the free-form variant's
``tuned_layer.LR_SCALE`` first), and measures its configured cells on the *training* split: a rate at
which the tuned layer forgets what the words say shows there as well, without looking at any test
sample. Writes results/tuned_rate.json.
"""
from __future__ import annotations

from harness import Benchmark, side_by_side


def run(scale: float, seed: int, profile_name: str) -> dict:
    import torch

    from pgae_lite.bert import tuned_encoder
    from pgae_lite.config import get_profile
    from pgae_lite.family.configured import evaluate_configured
    from pgae_lite.family.train import family_recipe, train_family
    from pgae_lite.runs.table1_unit import worker_dataset

    torch.set_num_threads(1)                  # one core per worker
    tuned_encoder.TUNED_LR_SCALE = scale      # read when the encoder is built
    profile = get_profile(profile_name, seed=seed)
    data = worker_dataset(None, profile, "cpu")
    recipe = family_recipe("PVAE-BERT-tuned", profile.train, profile.name, len(data.split("train")))
    trained = train_family("PVAE-BERT-tuned", data, profile.model, recipe, device="cpu")
    cells, _ = evaluate_configured(trained.model, data, trained.normaliser, split="train")
    return {"scale": scale, "seed": seed, "train_seconds": round(trained.seconds, 1),
            "training_split": {s: {k: c[k] for k in ("accuracy", "nrmse")} for s, c in cells.items()}}


def main() -> None:
    from pgae_lite.bert.tuned_layer import LR_SCALE

    bench = Benchmark("tuned_rate", __doc__, seeds=[0])
    bench.parser.add_argument("--scales", type=float, nargs="+", default=[LR_SCALE, LR_SCALE / 10])
    bench.add_workers(2, "trainings")
    args = bench.parse()
    runs = side_by_side(run, [(s, seed, args.profile) for s in args.scales for seed in args.seeds], args.workers)
    for r in runs:
        cells = r["training_split"]
        print(f"scale {r['scale']:g}, seed {r['seed']}: describe {cells['describe']['accuracy']:.2f}%, repeat "
              f"language {cells['repeat language']['accuracy']:.2f}%, execute {cells['execute']['nrmse']:.3f}%")
    bench.write({"split": "train", "runs": runs})


if __name__ == "__main__":
    main()
