"""Seconds per training epoch on each device: the paper's batch (6) against the book recipe's.

    python benchmarks/device_epoch.py [--original-data PATH] [--profile paper] [--epochs 3]
                                      [--batches 6 16] [--devices cpu cuda] [--threads 2]

Trains the PGAE row on the authors' data with :func:`pgae_lite.train.loop.train`, unchanged, for
``--epochs`` epochs of the profile (default ``paper``: peephole cells, one LSTM step per time
step, Adam 1e-5) at each batch size (default: the paper's 6 and the book recipe's), on each
device (default: the CPU, and CUDA where torch sees it). The first epoch is reported apart
(it pays for warm-up: kernel selection, allocator); ``s_per_epoch`` is the mean of the later
ones. Writes results/device_epoch.json; run it on an otherwise idle machine.
"""
from __future__ import annotations

import time

import torch
from harness import Benchmark

from pgae_lite.config import get_profile
from pgae_lite.data.original import load_original
from pgae_lite.train.loop import train


def epoch_seconds(dataset, profile, device: str) -> list[float]:
    """Wall time of each epoch of one training (``loss.item()`` each step syncs the device)."""
    stamps = [time.perf_counter()]
    train(dataset, profile, device=device, progress=False,
          callback=lambda epoch, model, record: stamps.append(time.perf_counter()))
    return [b - a for a, b in zip(stamps, stamps[1:])]


def main() -> None:
    bench = Benchmark("device_epoch", __doc__)
    bench.parser.set_defaults(profile="paper")
    bench.parser._option_string_actions["--profile"].help = "the recipe's profile (default: paper)"
    bench.add_original_data()
    bench.parser.add_argument("--epochs", type=int, default=3, help="epochs per training (>= 2)")
    bench.parser.add_argument("--batches", type=int, nargs="+",
                              default=[6, get_profile("book").train.batch_size])
    bench.parser.add_argument("--devices", nargs="+", default=None,
                              help="default: cpu, and cuda when torch sees a GPU")
    args = bench.parse()
    if args.epochs < 2:
        bench.parser.error(f"--epochs must be at least 2 (the first is warm-up), got {args.epochs}")
    devices = args.devices or ["cpu"] + (["cuda"] if torch.cuda.is_available() else [])
    base = get_profile(args.profile)                            # resolved once, here
    dataset = load_original(args.original_data)
    rows = []
    for device in devices:
        for batch in args.batches:
            profile = get_profile(base, seed=args.seeds[0], epochs=args.epochs, batch_size=batch)
            times = epoch_seconds(dataset, profile, device)
            row = {"device": device, "batch": batch, "first_epoch_s": round(times[0], 2),
                   "s_per_epoch": round(sum(times[1:]) / len(times[1:]), 2),
                   "steps_per_epoch": -(-len(dataset.split("train")) // batch)}
            rows.append(row)
            print(row, flush=True)
    bench.write({"data": "original", "epochs": args.epochs, "cell": base.model.cell,
                 "rows": rows})


if __name__ == "__main__":
    main()
