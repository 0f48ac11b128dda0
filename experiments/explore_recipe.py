"""Exploration: train with periodic test evaluation (learning curve).

    python experiments/explore_recipe.py --epochs 300 --seed 0 [--sim] [--set key=value ...] [--model key=value ...]

On the authors' data by default; ``--sim`` uses the book profile's simulated data.
``--opposite`` also scores the opposite agent's view (PGAE-opposite; cells prefixed ``opp_``),
for the two-view model (``--set opposite_prob=0.5``).
"""
import argparse
import json
import time
from dataclasses import replace
from pathlib import Path

import torch

from pgae_lite.config import get_profile
from pgae_lite.data.original import load_original
from pgae_lite.evaluate.table1 import evaluate
from pgae_lite.runs.data import simulated_dataset
from pgae_lite.train.loop import train


def overrides(pairs):
    return {k: json.loads(v) if v[:1] in "0123456789.-[{tfn" else v for k, v in (s.split("=", 1) for s in pairs)}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--original-data", metavar="PATH", default="../shared/pgae-original-data",
                    help="the authors' data folder")
    ap.add_argument("--epochs", type=int, default=300)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--every", type=int, default=25)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--set", nargs="*", default=[], help="TrainConfig overrides key=value")
    ap.add_argument("--model", nargs="*", default=[], help="ModelConfig overrides key=value")
    ap.add_argument("--sim", action="store_true", help="the simulated data (book profile) instead of the authors'")
    ap.add_argument("--opposite", action="store_true", help="also score the opposite view (opp_ cells)")
    ap.add_argument("--log", default=None)
    ap.add_argument("--save", default=None, help="folder for the checkpoint (default: none saved)")
    a = ap.parse_args()
    torch.set_num_threads(a.threads)

    prof = get_profile("book", epochs=a.epochs, seed=a.seed, **overrides(a.set))     # resolved once, here
    prof.model = replace(prof.model, **overrides(a.model))
    ds = simulated_dataset(prof, progress=False) if a.sim else load_original(a.original_data)
    t0 = time.perf_counter()
    rows = []

    def cb(epoch, model, rec):
        if epoch % a.every and epoch != a.epochs:
            return
        t = time.perf_counter() - t0
        from pgae_lite.data.normaliser import Normaliser
        norm = Normaliser.fit(ds.split("train"), prof.train.vision_scaling)
        res, _ = evaluate(model, ds, norm)
        line = {"epoch": epoch, "t": round(t), **{k: round(v["accuracy"], 2) for k, v in res.items()},
                **{k.replace(" ", "_")[:9] + "_e": round(v["nrmse"], 3) for k, v in res.items()},
                "loss": round(rec["loss"], 4),
                "gate": {k: round(v, 2) for k, v in rec["gate"].items()}}
        if a.opposite:
            opp, _ = evaluate(model, ds, norm, opposite=True)
            line["opp_describe"] = round(opp["describe"]["accuracy"], 2)
            line["opp_repeat_a_e"] = round(opp["repeat action"]["nrmse"], 3)
        rows.append(line)
        print(json.dumps(line), flush=True)

    tr = train(ds, prof, out_dir=a.save, progress=False, callback=cb)
    print("train seconds", round(tr.seconds))
    if a.log:
        Path(a.log).write_text(json.dumps({"argv": vars(a), "train_seconds": tr.seconds, "rows": rows}))


if __name__ == "__main__":   # --sim may record the data: its workers are spawned and re-import this file
    main()
