"""What the ``paper`` profile costs here: each family row's authors' recipe, a few epochs timed, the whole projected.

    python benchmarks/paper_cost.py [--original-data PATH] [--rows PRAE PVAE ...] [--epochs 2] [--workers 2]

Each row trains on the authors' data under the ``paper`` profile, exactly as ``reproduce --profile
paper`` would train it (PRAE, PVAE and PVAE-BERT(-tuned): their authors' iterations, batch and rate,
``Training.authors_steps``; PGAE, PGAE-BERT: the PGAE paper's; PTAE: its own authors' width,
dropout and 2,500 epochs, ``Training.authors_model``/``authors_train``; ``pgae_lite.runs.rows``), but for
``--epochs`` epochs only, one core each. ``s_per_epoch`` is the time of those epochs over their
number; ``projected_h`` the whole recipe's epochs at that rate, in hours, on this machine. Writes
results/paper_cost.json.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from harness import Benchmark, side_by_side

if TYPE_CHECKING:
    from pgae_lite.config import Profile

CONFIGURED = ("PRAE", "PVAE", "PVAE-BERT", "PVAE-BERT-tuned")
ROWS = (*CONFIGURED, "PGAE", "PGAE-BERT", "PTAE")


def run(row: str, epochs: int, profile: Profile, original_data: str) -> dict:
    from dataclasses import replace

    import torch

    from pgae_lite.config import get_profile
    from pgae_lite.model.pgae import count_parameters
    from pgae_lite.runs.data import worker_dataset
    from pgae_lite.runs.pipeline import unit_profile
    from pgae_lite.runs.rows import ROWS as BOOK_ROWS
    from pgae_lite.train.loop import train

    torch.set_num_threads(1)                  # one core per worker
    base = get_profile(profile, seed=0)
    data = worker_dataset(original_data, base, "cpu")
    samples = len(data.split("train"))
    prof = unit_profile(base, BOOK_ROWS[row].training, 0, data)        # the authors' recipe, under paper
    trained = train(data, replace(prof, train=replace(prof.train, epochs=epochs)), device="cpu",
                    progress=False, name=row)
    per_epoch = trained.seconds / epochs
    steps = -(-samples // prof.train.batch_size)
    return {"row": row, "epochs": prof.train.epochs, "batch": prof.train.batch_size, "lr": prof.train.lr,
            "steps_per_epoch": steps, "timed_epochs": epochs, "s_per_epoch": round(per_epoch, 2),
            "projected_h": round(per_epoch * prof.train.epochs / 3600, 2),
            "parameters": count_parameters(trained.model)}


def main() -> None:
    bench = Benchmark("paper_cost", __doc__, seeds=[0])
    bench.parser.set_defaults(profile="paper")
    bench.parser._option_string_actions["--profile"].help = "the recipe's profile (default: paper)"
    bench.add_original_data()
    bench.parser.add_argument("--rows", nargs="+", default=list(ROWS), choices=ROWS)
    bench.parser.add_argument("--epochs", type=int, default=2, help="epochs timed per row (>= 1)")
    bench.add_workers(2, "trainings")
    args = bench.parse()
    if args.epochs < 1:
        bench.parser.error(f"--epochs must be at least 1; got {args.epochs}")
    if not args.original_data:
        bench.parser.error("the paper profile's cost is measured on the authors' data: give --original-data")
    from pgae_lite.config import get_profile
    profile = get_profile(args.profile)                  # resolved once, here
    jobs = [(row, args.epochs, profile, args.original_data) for row in args.rows]
    runs = side_by_side(run, jobs, args.workers)
    for r in runs:
        print(f"{r['row']:16} {r['epochs']:>6} epochs of {r['steps_per_epoch']:>4} steps (batch {r['batch']}): "
              f"{r['s_per_epoch']:.2f} s each, {r['projected_h']:.1f} h in all")
    bench.write({"rows": runs})


if __name__ == "__main__":
    main()
