"""Open vs closed loop in the simulator: does the robot do what it was told?

    python benchmarks/closed_loop.py runs/simulated-book-seed0/checkpoint.pt [--profile book]
                                     [--limit 24] [--no-tracking] [--out benchmarks/out/closed_loop.json]

Loads a PGAE checkpoint trained on the profile's simulated data, the profile's
CAE and dataset (cached), and executes each test episode twice
(:func:`pgae_lite.closedloop.compare`): open loop, the paper's execute (the
decoder reads the recorded vision), and closed loop (it reads what its own
motion shows). Prints the success rate per action and speed and the time per
episode; writes the per-episode table and the summary as JSON. ``--limit N``
takes N episodes evenly spread over the 216 of the test split. Run it with
``OMP_NUM_THREADS=1``: the models are small, a second thread does not help.

The book's PGAE copies from the recorded pictures and drifts in closed loop;
the training ``PGAE-closed`` (``pgae_lite.config.TRAININGS``) is the one
made for it, e.g. ``python benchmarks/explore_recipe.py --sim --epochs 1200
--set decoder_vision_dropout=0.5 decoder_vision_warp=0.5 --save runs/closed``.
"""
from __future__ import annotations

import argparse
import os
import time

import torch

from pgae_lite.closedloop import compare, success_summary
from pgae_lite.config import get_profile
from pgae_lite.pipeline import simulated_dataset, trained_cae
from pgae_lite.train import load_model

from _report import write_report   # benchmarks/_report.py (the script's folder is on sys.path)

ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
ap.add_argument("checkpoint", help="a PGAE checkpoint trained on the profile's simulated data")
ap.add_argument("--profile", default="book", help="simulated dataset and CAE profile (default: book)")
ap.add_argument("--limit", type=int, default=None, help="this many test episodes, evenly spread (default: all)")
ap.add_argument("--no-tracking", action="store_true", help="send the model's joints to the motors as they are")
ap.add_argument("--out", default="benchmarks/out/closed_loop.json")
args = ap.parse_args()

torch.set_num_threads(int(os.environ.get("OMP_NUM_THREADS", "1")))
cae, _ = trained_cae(args.profile, "cpu", progress=False)
data = simulated_dataset(args.profile, "cpu", progress=False)
model, normaliser, ckpt = load_model(args.checkpoint, "cpu", data)   # refuses another cache's features

t0 = time.perf_counter()
table = compare(model, cae, normaliser, data, limit=args.limit, config=get_profile(args.profile).data,
                tracking=not args.no_tracking)
seconds = time.perf_counter() - t0
summary = success_summary(table)

print(summary.round(2).to_string())
print(f"\n{len(table)} episodes in {seconds:.0f} s: {seconds / len(table):.2f} s per episode "
      f"(open loop {table['open_seconds'].mean():.2f} s, closed loop {table['closed_seconds'].mean():.2f} s)")
failed = table[~table["closed_passed"]]
if len(failed):
    print(f"\nclosed-loop failures: {len(failed)} (the first 10; all of them in the JSON)")
    print(failed[["id", "description", "open_passed", "closed_nrmse", "closed_reason"]].head(10).to_string(index=False))

write_report(args.out, table, summary, seconds,
             checkpoint=args.checkpoint, profile=args.profile, limit=args.limit,
             tracking=not args.no_tracking, model=ckpt["profile"]["model"])
