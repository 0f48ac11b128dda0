"""Command line: ``python -m pgae_lite reproduce --original-data PATH``.

Trains PGAE (or resumes an interrupted run) in the chosen profile, evaluates
it on the test split as in the paper's Table 1, prints the table next to the
paper's row and writes ``results.json`` and ``predictions.npz`` to the
output folder.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

PROFILE_NAMES = ("smoke", "book", "paper")  # pgae_lite.config.PROFILES (not imported: --help stays instant)
PROFILE_ENV = "PGAE_LITE_PROFILE"
ORIGINAL_DATA_ENV = "PGAE_ORIGINAL_DATA"


def reproduce(original_data: str | Path | None = None, profile: str | None = None, seed: int = 0,
              out_dir: str | Path | None = None, epochs: int | None = None,
              device: str | None = None, progress: bool = True) -> dict:
    """Train (or resume) and evaluate; write results.json and predictions.npz; return the results.

    ``original_data`` is the authors' data folder; ``None`` runs the whole pipeline on
    our simulated data (simulator -> CAE -> PGAE, each step cached).
    """
    import numpy as np

    from .config import get_profile
    from .data import load_original
    from .evaluate import PAPER_TABLE, evaluate, format_table
    from .train import train

    overrides = {"seed": seed} | ({"epochs": epochs} if epochs else {})
    prof = get_profile(profile, **overrides)
    if original_data:
        dataset, source = load_original(original_data), "original"
    else:
        from .pipeline import simulated_dataset
        dataset, source = simulated_dataset(prof.name, device, progress), "simulated"
    out = Path(out_dir or f"runs/{source}-{prof.name}-seed{seed}")
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    trained = train(dataset, prof, out_dir=out, device=device, progress=progress)
    results, preds = evaluate(trained.model, dataset, trained.normaliser)
    row = "PGAE (ours)"
    report = {
        "row": "PGAE", "data": str(original_data) if original_data else dataset.source, "profile": prof.to_dict(), "seed": seed,
        "device": str(next(trained.model.parameters()).device),
        "train_seconds": trained.seconds, "wall_seconds": time.perf_counter() - t0,
        "results": results, "paper": {s: {"accuracy": a, "nrmse": e} for s, (a, e) in PAPER_TABLE["PGAE"].items()},
        "final_loss": trained.history[-1] if trained.history else None,
    }
    (out / "results.json").write_text(json.dumps(report, indent=2))
    arrays = {}
    for signal, p in preds.items():
        key = signal.replace(" ", "_")
        arrays[f"{key}_ids"] = p.ids.astype(str)
        arrays[f"{key}_text"] = np.asarray(p.text, dtype=str)
        arrays[f"{key}_joints"] = p.joints
    tmp = out / "predictions.tmp.npz"
    np.savez_compressed(tmp, **arrays)
    os.replace(tmp, out / "predictions.npz")
    print(format_table({row: results}, {row: "PGAE"}))
    print(f"\nprofile {prof.name}, seed {seed}, training {trained.seconds:.0f} s; wrote {out/'results.json'} "
          f"and {out/'predictions.npz'}")
    return report


def simulate(profile: str | None = None, workers: int | None = None, progress: bool = True) -> int:
    """Record the profile's simulated dataset (or complete it) and print what was done."""
    from .simdata import DATASET_PROFILES, generate

    name = profile or os.environ.get(PROFILE_ENV, "book")
    report = generate(DATASET_PROFILES[name], workers=workers, progress=progress)
    print(f"{report.episodes} episodes in {report.folder} ({report.megabytes:.1f} MB); recorded {report.recorded} "
          f"in {report.seconds:.1f} s, {report.corrupt} damaged files replaced; "
          f"valid on the first try: {100 * report.first_try:.1f}%")
    return 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m pgae_lite", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    rep = sub.add_parser("reproduce", help="train and evaluate PGAE, print Table 1",
                         description="Train PGAE (resuming an interrupted run in the same output folder), "
                                     "evaluate it on the test split and print Table 1 beside the paper's row.")
    rep.add_argument("--original-data", metavar="PATH", default=os.environ.get(ORIGINAL_DATA_ENV),
                     help="the authors' data folder (holding target/ and actions.txt); "
                          f"default: ${ORIGINAL_DATA_ENV}; without either, our simulated data "
                          "(recorded, CAE-encoded and cached on first use)")
    rep.add_argument("--profile", choices=PROFILE_NAMES, default=None,
                     help=f"training recipe (default: ${PROFILE_ENV}, else 'book')")
    rep.add_argument("--seed", type=int, default=0, help="random seed (default 0): same seed, same numbers")
    rep.add_argument("--epochs", type=int, default=None, help="override the profile's number of epochs")
    rep.add_argument("--out", metavar="DIR", default=None,
                     help="output folder for checkpoint.pt, results.json, predictions.npz "
                          "(default: runs/original-PROFILE-seedSEED or runs/simulated-PROFILE-seedSEED)")
    rep.add_argument("--device", default=None, help="torch device, e.g. cpu or cuda (default: CUDA if present)")
    rep.add_argument("--no-progress", action="store_true", help="no progress bar")
    sim = sub.add_parser("simulate", help="record the simulated dataset into the cache",
                         description="Record every episode of the profile's dataset (144 patterns x 6 "
                                     "variations in the book profile) with the pybullet simulator, in "
                                     "parallel, into the cache ($PGAE_LITE_CACHE, else ~/.cache/pgae_lite). "
                                     "Episodes already recorded are kept; an interrupted run resumes.")
    sim.add_argument("--profile", choices=PROFILE_NAMES, default=None,
                     help=f"dataset size (default: ${PROFILE_ENV}, else 'book')")
    sim.add_argument("--workers", type=int, default=None, help="parallel processes (default: one per CPU core)")
    sim.add_argument("--no-progress", action="store_true", help="no progress bar")
    args = parser.parse_args(argv)
    if args.command == "simulate":
        return simulate(args.profile, args.workers, not args.no_progress)
    if args.command == "reproduce":
        from .data import DataFormatError
        from .train import CheckpointMismatchError

        try:
            reproduce(args.original_data, args.profile, args.seed, args.out, args.epochs,
                      args.device, not args.no_progress)
        except (DataFormatError, CheckpointMismatchError) as e:
            print(f"error: {e}", file=sys.stderr)
            return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
