"""Table 1 (PGAE row) on the authors' data: several seeds, each cell's median.

    python benchmarks/table1_original.py [--data PATH] [--seeds 0 1 2] [--profile book]
                                          [--jobs 1] [--threads 2]

Each seed runs ``python -m pgae_lite reproduce`` in its own process and
output folder under benchmarks/out/ (so an interrupted benchmark resumes).
``--jobs 2 --threads 1`` runs two seeds at once, one core each: more
throughput on a 2-core machine, but then each run's wall time is not the
time of a run alone; measure that with ``--jobs 1 --threads 2``.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from pgae_lite.evaluate import PAPER_TABLE
from pgae_lite.language import TEST_SIGNALS

ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
ap.add_argument("--data", default=os.environ.get("PGAE_ORIGINAL_DATA", "../shared/pgae-original-data"))
ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
ap.add_argument("--profile", default="book")
ap.add_argument("--jobs", type=int, default=1)
ap.add_argument("--threads", type=int, default=2)
ap.add_argument("--out", default="benchmarks/out")
args = ap.parse_args()


def run(seed: int) -> dict:
    out = Path(args.out) / f"table1-{args.profile}-seed{seed}"
    if (out / "results.json").exists():                  # a finished run: read it, don't redo it
        return json.loads((out / "results.json").read_text())
    env = dict(os.environ, OMP_NUM_THREADS=str(args.threads))
    subprocess.run([sys.executable, "-m", "pgae_lite", "reproduce", "--original-data", args.data,
                    "--profile", args.profile, "--seed", str(seed), "--out", str(out), "--no-progress",
                    "--device", "cpu"], check=True, env=env, stdout=subprocess.DEVNULL)
    report = json.loads((out / "results.json").read_text())
    return report


with ThreadPoolExecutor(args.jobs) as pool:
    reports = list(pool.map(run, args.seeds))

paper = PAPER_TABLE["PGAE"]
lines = [f"{'':18s}" + "".join(f"{s:>17s}" for s in TEST_SIGNALS) + f"{'train s':>10s}"]
for r in reports:
    res = r["results"]
    lines.append(f"seed {r['seed']:<4d} acc %    " + "".join(f"{res[s]['accuracy']:17.2f}" for s in TEST_SIGNALS)
                 + f"{r['train_seconds']:10.0f}")
    lines.append(f"{'':10s}nRMSE %  " + "".join(f"{res[s]['nrmse']:17.3f}" for s in TEST_SIGNALS))
med = {s: {k: statistics.median(r["results"][s][k] for r in reports) for k in ("accuracy", "nrmse", "nrmse_padded")}
       for s in TEST_SIGNALS}
lines.append("median   acc %    " + "".join(f"{med[s]['accuracy']:17.2f}" for s in TEST_SIGNALS))
lines.append("         nRMSE %  " + "".join(f"{med[s]['nrmse']:17.3f}" for s in TEST_SIGNALS))
lines.append("paper    acc %    " + "".join(f"{paper[s][0]:17.2f}" for s in TEST_SIGNALS))
lines.append("         nRMSE %  " + "".join(f"{paper[s][1]:17.3f}" for s in TEST_SIGNALS))
verdict = {s: {"accuracy": med[s]["accuracy"] >= paper[s][0], "nrmse": med[s]["nrmse"] <= paper[s][1]}
           for s in TEST_SIGNALS}
lines.append("median at or better than the paper: " + json.dumps(verdict))
print("\n".join(lines))
Path(args.out).mkdir(parents=True, exist_ok=True)
(Path(args.out) / f"table1-{args.profile}.json").write_text(json.dumps(
    {"seeds": [{"seed": r["seed"], "train_seconds": r["train_seconds"], "results": r["results"]} for r in reports],
     "median": med, "paper": paper, "verdict": verdict, "jobs": args.jobs, "threads": args.threads}, indent=2))
