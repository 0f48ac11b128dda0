"""The same numbers before and after a change of the code's shape: two commits side by side.

    python benchmarks/same_behaviour.py --base REV [--head REV] [--reuse] [--profile smoke]
                                        [--rows every] [--data original|ours] [--side-models]
                                        [--seeds 0] [--original-data PATH]

Each commit (``--base``, and ``--head``: the checkout's HEAD by default) is checked
out into a temporary worktree and runs ``python -m pgae_lite reproduce`` with a cache
of its own (nothing shared, so each side records its data and trains every model
itself), one thread, the same seed: on the authors' data (``--data original``, the
default) or on our simulated data (``--data ours``). ``--rows`` takes reproduce's rows,
``all`` (Table 1's) or ``every`` (Table 1's and the family's). With ``--side-models`` each
side also trains, through its cached pipeline on our simulated data, the models of the
book that are no row (:data:`SIDE_MODELS`: the free-form variant, PGAE without its plan
head, chapter 09's PRAE on all 8 descriptions) and saves their weights. The two sides run
at the same time, one core each. With ``--reuse`` the head side starts from a copy of the
base side's output folder instead: it trains nothing and evaluates the base's trained
models (a change that needs no retraining).

Then every model's weights are compared tensor by tensor (``torch.equal``; a saved value
that is no tensor, with ``==``), every number of ``results.json``'s rows, and every array
of every predictions file. Writes results/same_behaviour-PROFILE[-DATA][-reused].json:
per model, whether its weights are bit-identical; per cell, both values; per predictions
file and array, whether they are equal; the counts of what differs (0 everywhere when the
change kept the behaviour).
"""
import json
import os
import shlex
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import torch
from harness import ROOT, Benchmark

EVERY_ROW = "PGAE,PGAE-BERT,PGAE-self,PGAE-opposite,PRAE,PVAE,PVAE-BERT,PVAE-BERT-tuned,PTAE"
#: The models of the book that are not rows of reproduce, by the name of their training.
SIDE_MODELS = ("PGAE-BERT-phrasings", "PGAE-no-plan", "PRAE-8")
#: Run in each side's worktree: train the side models through its pipeline, save their weights.
#: It reads the trainings by name through the registry of the side's commit (runs.rows since the
#: change of issue 59; runs.trainings and runs.family_models before).
SIDE_SCRIPT = r"""
import sys
from pathlib import Path

import torch

out, profile, seed = Path(sys.argv[1]), sys.argv[2], int(sys.argv[3])
out.mkdir(parents=True, exist_ok=True)
try:
    from pgae_lite.runs.rows import training_named
    from pgae_lite.runs.pipeline import trained_models
    from pgae_lite.config import get_profile

    names = sys.argv[4:]
    trained = trained_models([training_named(n) for n in names], get_profile(profile), seed, progress=False)
    models = {n: trained[n].model for n in names}
except ImportError:                                  # before issue 59
    from pgae_lite.runs.family_models import family_models
    from pgae_lite.runs.pipeline import trained_pgae
    from pgae_lite.runs.trainings import by_name

    models = {n: trained_pgae(by_name(n), profile, seed, progress=False).model
              for n in sys.argv[4:] if n != "PRAE-8"}
    if "PRAE-8" in sys.argv[4:]:
        models["PRAE-8"] = family_models(profile, seed, progress=False, workers=1)["PRAE-8"].model
for name, model in models.items():
    (out / name).mkdir()
    torch.save({"model": model.state_dict()}, out / name / "checkpoint.pt")
"""

bench = Benchmark("same_behaviour", __doc__)
bench.parser.add_argument("--base", required=True, help="the commit to compare HEAD with")
bench.parser.add_argument("--head", default="HEAD", help="the commit compared with the base (default: HEAD; "
                          "'.': this checkout as it is, uncommitted changes included)")
bench.parser.add_argument("--reuse", action="store_true", help="the head evaluates the base's trained models")
bench.parser.add_argument("--rows", default="all", help="rows as reproduce takes them, or 'every' (default: all)")
bench.parser.add_argument("--data", choices=("original", "ours"), default="original",
                          help="the authors' data (default) or our simulated data")
bench.parser.add_argument("--side-models", action="store_true",
                          help=f"also the models that are no row: {', '.join(SIDE_MODELS)}")
bench.add_original_data()


def git(*args: str) -> str:
    return subprocess.run(["git", *args], cwd=ROOT, capture_output=True, text=True, check=True).stdout.strip()


def start(side: str, rev: str, work: Path, args, start_from: Path | None = None) -> tuple[Path, list]:
    """Start ``reproduce`` (and the side models) at commit ``rev`` in a worktree of its own; the output folder
    (a copy of ``start_from``) and the process."""
    tree, out = (ROOT if rev == "." else work / f"tree-{side}"), work / f"out-{side}"
    if start_from is not None:
        shutil.copytree(start_from, out)
    if rev != ".":
        git("worktree", "add", "--detach", str(tree), rev)
    env = {**os.environ, "PYTHONPATH": str(tree), "PGAE_LITE_CACHE": str(work / f"cache-{side}"),
           "OMP_NUM_THREADS": "1", "PYTHONHASHSEED": "0", "PGAE_LITE_PROFILE": args.profile}
    env.pop("PGAE_ORIGINAL_DATA", None)
    data = ["--original-data", str(Path(args.original_data).resolve())] if args.data == "original" else []
    rows = EVERY_ROW if args.rows == "every" else args.rows
    command = [sys.executable, "-m", "pgae_lite", "reproduce", *data, "--profile", args.profile, "--rows", rows,
               "--seed", str(args.seeds[0]), "--out", str(out), "--no-progress", "--device", "cpu", "--workers", "1"]
    log = open(work / f"log-{side}.txt", "w")
    script = (f"{' '.join(command)} && {sys.executable} -c {shlex.quote(SIDE_SCRIPT)} {out / 'side'} "
              f"{args.profile} {args.seeds[0]} {' '.join(SIDE_MODELS)}") if args.side_models else None
    process = subprocess.Popen(["bash", "-c", script] if script else command, cwd=tree, env=env,
                               stdout=log, stderr=subprocess.STDOUT)
    return out, [process, tree, log]


def finish(rev: str, handle: list) -> None:
    process, tree, log = handle
    rc = process.wait()
    log.close()
    if rev != ".":
        git("worktree", "remove", "--force", str(tree))
    if rc:
        raise SystemExit(f"{rev}: the run failed (exit {rc}); its output:\n{Path(log.name).read_text()[-3000:]}")


def numbers(node, path=()) -> dict:
    """Every number of a report's rows, by its path (row, signal, cell); None (N.A.) kept."""
    if isinstance(node, dict):
        return {k: v for key, child in node.items() for k, v in numbers(child, path + (key,)).items()}
    if node is None or (isinstance(node, (int, float)) and not isinstance(node, bool)):
        return {"/".join(map(str, path)): node}
    return {}


def weights_of(folder: Path) -> dict | None:
    """The saved weights in a model's folder (its checkpoint, or a family model's file before issue 59)."""
    for name in ("checkpoint.pt", "family.pt"):
        if (folder / name).exists():
            return torch.load(folder / name, weights_only=True)["model"]
    return None


def same(a, b) -> bool:
    if torch.is_tensor(a) and torch.is_tensor(b):
        return a.dtype == b.dtype and a.shape == b.shape and bool(torch.equal(a, b))
    return a == b


def compare(base: Path, head: Path) -> dict:
    weights = {}
    folders = sorted(p for p in [*base.iterdir(), *(base / "side").glob("*")] if p.is_dir() and p.name != "logs")
    for folder in folders:
        a = weights_of(folder)
        if a is None:
            continue
        b = weights_of(head / folder.relative_to(base)) or {}
        weights[str(folder.relative_to(base))] = {"tensors": len(a), "identical": a.keys() == b.keys()
                                                  and all(same(a[k], b[k]) for k in a)}
    cells_a = numbers(json.loads((base / "results.json").read_text())["rows"])
    cells_b = numbers(json.loads((head / "results.json").read_text())["rows"])
    cells = {k: [cells_a[k], cells_b.get(k, "missing")] for k in cells_a}
    arrays = {}
    for path in sorted(base.rglob("*.npz")):
        name = str(path.relative_to(base))
        pa, pb = np.load(path), np.load(head / name)
        for k in pa.files:
            arrays[f"{name}:{k}"] = k in pb.files and bool(np.array_equal(pa[k], pb[k],
                                                                          equal_nan=pa[k].dtype.kind == "f"))
    return {"weights": weights, "cells": cells, "prediction_arrays": arrays,
            "differ": {"models": sum(not w["identical"] for w in weights.values()),
                       "cells": sum(a != b for a, b in cells.values()),
                       "prediction_arrays": sum(not equal for equal in arrays.values())},
            "compared": {"models": len(weights), "cells": len(cells), "prediction_arrays": len(arrays)}}


if __name__ == "__main__":
    args = bench.parse()
    bench.name = (f"same_behaviour-{args.profile}" + ("-ours" if args.data == "ours" else "")
                  + ("-reused" if args.reuse else ""))
    base = git("rev-parse", "--short", args.base)
    head = "." if args.head == "." else git("rev-parse", "--short", args.head)
    with tempfile.TemporaryDirectory() as work:
        work = Path(work)
        before, handle = start("base", base, work, args)
        if args.reuse:
            finish(base, handle)
            after, handle = start("head", head, work, args, start_from=before)
            finish(head, handle)
        else:
            after, head_handle = start("head", head, work, args)
            finish(base, handle)
            finish(head, head_handle)
        result = compare(before, after)
    print(json.dumps({"compared": result["compared"], "differ": result["differ"]}), flush=True)
    rows = EVERY_ROW if args.rows == "every" else args.rows
    bench.write({"base": base, "head": head, "reused": args.reuse, "rows": rows, "data": args.data,
                 "side_models": list(SIDE_MODELS) if args.side_models else [], **result})
