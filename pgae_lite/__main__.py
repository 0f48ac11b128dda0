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


def reproduce(original_data: str | Path, profile: str | None = None, seed: int = 0,
              out_dir: str | Path | None = None, epochs: int | None = None,
              device: str | None = None, progress: bool = True) -> dict:
    """Train (or resume) and evaluate; write results.json and predictions.npz; return the results."""
    import numpy as np

    from .config import get_profile
    from .data import load_original
    from .evaluate import PAPER_TABLE, evaluate, format_table
    from .train import train

    overrides = {"seed": seed} | ({"epochs": epochs} if epochs else {})
    prof = get_profile(profile, **overrides)
    dataset = load_original(original_data)
    out = Path(out_dir or f"runs/original-{prof.name}-seed{seed}")
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    trained = train(dataset, prof, out_dir=out, device=device, progress=progress)
    results, preds = evaluate(trained.model, dataset, trained.normaliser)
    row = "PGAE (ours)"
    report = {
        "row": "PGAE", "data": str(original_data), "profile": prof.to_dict(), "seed": seed,
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


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m pgae_lite", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    rep = sub.add_parser("reproduce", help="train and evaluate PGAE, print Table 1",
                         description="Train PGAE (resuming an interrupted run in the same output folder), "
                                     "evaluate it on the test split and print Table 1 beside the paper's row.")
    rep.add_argument("--original-data", metavar="PATH", default=os.environ.get(ORIGINAL_DATA_ENV),
                     help="the authors' data folder (holding target/ and actions.txt); "
                          f"default: ${ORIGINAL_DATA_ENV}")
    rep.add_argument("--profile", choices=PROFILE_NAMES, default=None,
                     help=f"training recipe (default: ${PROFILE_ENV}, else 'book')")
    rep.add_argument("--seed", type=int, default=0, help="random seed (default 0): same seed, same numbers")
    rep.add_argument("--epochs", type=int, default=None, help="override the profile's number of epochs")
    rep.add_argument("--out", metavar="DIR", default=None,
                     help="output folder for checkpoint.pt, results.json, predictions.npz "
                          "(default: runs/original-PROFILE-seedSEED)")
    rep.add_argument("--device", default=None, help="torch device, e.g. cpu or cuda (default: CUDA if present)")
    rep.add_argument("--no-progress", action="store_true", help="no progress bar")
    args = parser.parse_args(argv)
    if args.command == "reproduce":
        if not args.original_data:
            parser.error("--original-data PATH is required (the authors' data folder from the public "
                         f"repository oo222bs/PGAE, or set ${ORIGINAL_DATA_ENV}); simulated data comes in a later version")
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
