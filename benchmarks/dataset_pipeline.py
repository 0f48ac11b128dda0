"""The simulated data pipeline, timed: recording, CAE training, feature extraction.

    python benchmarks/dataset_pipeline.py [--profile book] [--cache DIR] [--workers N] [--skip-cae] [--threads 2]

Uses an empty cache folder (a new temporary one unless ``--cache`` is given),
so every step really runs. Prints the figures after each step and writes
results/dataset_pipeline.json: wall seconds per step, episodes, first-try
success, size on disk. Run it on an otherwise idle machine.
"""
from __future__ import annotations

import os
import tempfile
import time

from harness import Benchmark


def main() -> None:
    bench = Benchmark("dataset_pipeline", __doc__)
    bench.parser.add_argument("--cache", default=None, help="cache folder (default: a new temporary folder)")
    bench.parser.add_argument("--workers", type=int, default=None, help="recording processes (default: one per core)")
    bench.parser.add_argument("--skip-cae", action="store_true", help="time the recording only")
    args = bench.parse()
    os.environ["PGAE_LITE_CACHE"] = args.cache or tempfile.mkdtemp(prefix="pgae-cache-")

    from pgae_lite.config import get_profile                   # after the cache is set
    from pgae_lite.runs.pipeline import simulated_dataset, trained_cae
    from pgae_lite.data.simulated import generate

    row = {"cache": os.environ["PGAE_LITE_CACHE"], "workers": args.workers}
    t0 = time.perf_counter()
    report = generate(get_profile(args.profile).data, workers=args.workers)
    row.update(record_s=round(time.perf_counter() - t0, 1), episodes=report.episodes,
               first_try_pct=round(100 * report.first_try, 2), megabytes=round(report.megabytes, 1))
    print(row, flush=True)
    if not args.skip_cae:
        t0 = time.perf_counter()
        _, history = trained_cae(args.profile)
        row.update(cae_s=round(time.perf_counter() - t0, 1), cae_final_loss=round(history[-1]["loss"], 4))
        t0 = time.perf_counter()
        ds = simulated_dataset(args.profile)
        row.update(features_s=round(time.perf_counter() - t0, 1), samples=len(ds))
        print(row, flush=True)
    bench.write(row)


if __name__ == "__main__":  # the recording workers are spawned: they re-import this file
    main()
