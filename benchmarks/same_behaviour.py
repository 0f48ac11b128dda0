"""The same numbers before and after a change of the code's shape: two commits side by side.

    python benchmarks/same_behaviour.py --base REV [--head REV] [--reuse] [--profile smoke] [--rows all]
                                        [--seeds 0] [--original-data PATH]

Each commit (``--base``, and ``--head``: the checkout's HEAD by default) is checked
out into a temporary worktree and runs ``python -m pgae_lite reproduce`` on the
authors' data with a cache of its own (nothing shared, so each side trains every
model itself), one thread, the same seed. With ``--reuse`` the head side starts
from a copy of the base side's output folder instead: it trains nothing and
evaluates the base's trained models (a code change that needs no retraining).
Then every model's weights are compared tensor by tensor (``torch.equal``), every
Table 1 cell of ``results.json`` number by number, and every array of
``predictions.npz``. Writes results/same_behaviour-PROFILE.json (with ``--reuse``,
same_behaviour-PROFILE-reused.json): per training, whether its weights are
bit-identical; per cell, both values; the counts of what differs (0 everywhere
when the change kept the behaviour).
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import torch

from harness import ROOT, Benchmark

bench = Benchmark("same_behaviour", __doc__)
bench.parser.add_argument("--base", required=True, help="the commit to compare HEAD with")
bench.parser.add_argument("--head", default="HEAD", help="the commit compared with the base (default: HEAD)")
bench.parser.add_argument("--reuse", action="store_true", help="the head evaluates the base's trained models")
bench.parser.add_argument("--rows", default="all", help="Table 1's rows, as reproduce takes them")
bench.add_original_data()


def git(*args: str) -> str:
    return subprocess.run(["git", *args], cwd=ROOT, capture_output=True, text=True, check=True).stdout.strip()


def run(rev: str, work: Path, args, start: Path | None = None) -> Path:
    """``reproduce`` at commit ``rev`` in a worktree of its own; its output folder (a copy of ``start``)."""
    tree, out = work / f"tree-{rev}", work / f"out-{rev}"
    if start is not None:
        shutil.copytree(start, out)
    git("worktree", "add", "--detach", str(tree), rev)
    try:
        env = {**os.environ, "PYTHONPATH": str(tree), "PGAE_LITE_CACHE": str(work / f"cache-{rev}"),
               "OMP_NUM_THREADS": "1", "PYTHONHASHSEED": "0", "PGAE_LITE_PROFILE": args.profile}
        subprocess.run([sys.executable, "-m", "pgae_lite", "reproduce", "--original-data", args.original_data,
                        "--profile", args.profile, "--rows", args.rows, "--seed", str(args.seeds[0]),
                        "--out", str(out), "--no-progress", "--device", "cpu"],
                       cwd=tree, env=env, check=True, stdout=subprocess.DEVNULL)
    finally:
        git("worktree", "remove", "--force", str(tree))
    return out


def numbers(node, path=()) -> dict:
    """Every number of a report's rows, by its path (row, signal, cell)."""
    if isinstance(node, dict):
        return {k: v for key, child in node.items() for k, v in numbers(child, path + (key,)).items()}
    if isinstance(node, (int, float)) and not isinstance(node, bool):
        return {"/".join(map(str, path)): node}
    return {}


def compare(base: Path, head: Path) -> dict:
    weights = {}
    for folder in sorted(p for p in base.iterdir() if p.is_dir()):
        a = torch.load(folder / "checkpoint.pt", weights_only=True)["model"]
        b = torch.load(head / folder.name / "checkpoint.pt", weights_only=True)["model"]
        weights[folder.name] = {"tensors": len(a), "identical": a.keys() == b.keys()
                                and all(torch.equal(a[k], b[k]) for k in a)}
    cells_a = numbers(json.loads((base / "results.json").read_text())["rows"])
    cells_b = numbers(json.loads((head / "results.json").read_text())["rows"])
    cells = {k: [cells_a[k], cells_b.get(k)] for k in cells_a}
    pa, pb = np.load(base / "predictions.npz"), np.load(head / "predictions.npz")
    arrays = {k: bool(np.array_equal(pa[k], pb[k], equal_nan=pa[k].dtype.kind == "f")) for k in pa.files}
    return {"weights": weights, "cells": cells, "prediction_arrays": arrays,
            "differ": {"models": sum(not w["identical"] for w in weights.values()),
                       "cells": sum(a != b for a, b in cells.values()),
                       "prediction_arrays": sum(not same for same in arrays.values())}}


if __name__ == "__main__":
    args = bench.parse()
    bench.name = f"same_behaviour-{args.profile}" + ("-reused" if args.reuse else "")
    base, head = git("rev-parse", "--short", args.base), git("rev-parse", "--short", args.head)
    with tempfile.TemporaryDirectory() as work:
        before = run(base, Path(work), args)
        result = compare(before, run(head, Path(work), args, start=before if args.reuse else None))
    print(json.dumps(result["differ"]), flush=True)
    bench.write({"base": base, "head": head, "reused": args.reuse, "rows": args.rows, **result})
