"""The simulated data pipeline, timed: recording, CAE training, feature extraction.

    python benchmarks/dataset_pipeline.py [--profile book] [--cache DIR] [--workers N]

Uses an empty cache folder (a new temporary one unless ``--cache`` is given),
so every step really runs. Prints and appends one JSON line to
``benchmarks/out/dataset_pipeline.jsonl``: wall seconds per step, episodes,
first-try success, size on disk. Run it on an otherwise idle machine.
"""
import argparse
import json
import os
import tempfile
import time
from pathlib import Path


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--profile", default="book")
    ap.add_argument("--cache", default=None, help="cache folder (default: a new temporary folder)")
    ap.add_argument("--workers", type=int, default=None)
    ap.add_argument("--skip-cae", action="store_true", help="time the recording only")
    args = ap.parse_args()
    os.environ["PGAE_LITE_CACHE"] = args.cache or tempfile.mkdtemp(prefix="pgae-cache-")

    from pgae_lite.pipeline import simulated_dataset, trained_cae  # after the cache is set
    from pgae_lite.config import get_profile
    from pgae_lite.simdata import generate

    row = {"profile": args.profile, "cache": os.environ["PGAE_LITE_CACHE"], "cpus": os.cpu_count()}
    t0 = time.perf_counter()
    report = generate(get_profile(args.profile).data, workers=args.workers)
    row.update(record_s=round(time.perf_counter() - t0, 1), episodes=report.episodes,
               first_try_pct=round(100 * report.first_try, 2), megabytes=round(report.megabytes, 1))
    print(json.dumps(row), flush=True)
    if not args.skip_cae:
        t0 = time.perf_counter()
        _, history = trained_cae(args.profile)
        row.update(cae_s=round(time.perf_counter() - t0, 1), cae_final_loss=round(history[-1]["loss"], 4))
        t0 = time.perf_counter()
        ds = simulated_dataset(args.profile)
        row.update(features_s=round(time.perf_counter() - t0, 1), samples=len(ds))
    print(json.dumps(row), flush=True)
    out = Path(__file__).parent / "out"
    out.mkdir(exist_ok=True)
    with open(out / "dataset_pipeline.jsonl", "a") as f:
        f.write(json.dumps(row) + "\n")


if __name__ == "__main__":  # the recording workers are spawned: they re-import this file
    main()
