"""The course's labs at their budget: each lab's run on the book's component and on its reference change.

    python benchmarks/labs.py --lab concat [--seeds 0 1 2] [--threads 2] [--profile book]

For the lab ``NAME`` (a module of ``pgae_lite.course.labs``), runs ``run(BASELINE, seed)`` and
``run(REFERENCE, seed)`` for every seed, each in a fresh process as a student's notebook runs it (torch's
threads: the machine's, two on the course's laptop, unless ``--threads``), and writes each run's figures and
wall-clock seconds (from the process's start of ``run`` to its end, the data read from a prepared cache) to
``results/lab-NAME.json``. The lab's notebook quotes these figures beside the student's own run, and the
instructor's page quotes the seconds: a lab fits a class period when its run takes at most 10 minutes.
"""
from __future__ import annotations

import multiprocessing
import time

from harness import Benchmark

from pgae_lite.course.labs import LABS, lab


def measure(name: str, variant: str, seed: int, profile: str, threads: int | None) -> dict:
    """One run of lab ``name`` with its ``variant`` component ("baseline" or "reference"), in this process."""
    import torch

    if threads:
        torch.set_num_threads(threads)
    module = lab(name)
    component = module.BASELINE if variant == "baseline" else module.REFERENCE
    start = time.perf_counter()
    figures = module.run(component, seed=seed, profile=profile)
    seconds = time.perf_counter() - start
    print(name, variant, seed, figures, f"{seconds:.1f} s", flush=True)
    return {"variant": variant, "seed": seed, "seconds": round(seconds, 1),
            "figures": {k: round(float(v), 4) for k, v in figures.items()}}


def main() -> None:
    bench = Benchmark("labs", __doc__, seeds=[0, 1, 2])
    bench.parser.add_argument("--lab", required=True, choices=LABS)
    args = bench.parse()
    bench.name = f"lab-{args.lab}"
    module = lab(args.lab)
    context = multiprocessing.get_context("spawn")      # a fresh process per run: nothing read twice is free
    runs = []
    for seed in args.seeds:
        for variant in ("baseline", "reference"):
            with context.Pool(1) as pool:
                runs.append(pool.apply(measure, (args.lab, variant, seed, args.profile, args.threads)))
    bench.write({"lab": args.lab, "title": module.TITLE, "figures": module.FIGURES, "runs": runs,
                 "longest_seconds": max(r["seconds"] for r in runs)})


if __name__ == "__main__":
    main()
