"""The sweep's engine against a process pool: one Table 1 sweep run three ways, its cells, the overhead per unit.

    python benchmarks/sweep_engine.py [--original-data PATH] [--rows PGAE] [--seeds 0 1 2] [--profile book]
                                      [--workers 2]

The same units (``reproduce``'s: one training of one seed, then its rows measured) run three
times, each time into a fresh folder, so every unit trains from scratch:

1. ``pool``: a ``concurrent.futures`` process pool of ``--workers`` spawned processes, the way
   ``trained_models`` and the benchmarks spread their trainings before the sweep;
2. ``local``: the sweep (``pgae_lite.runs.sweep.run_sweep``) on a Dask ``LocalCluster`` of
   ``--workers`` single-threaded workers, what ``reproduce --seeds N`` does;
3. ``separate``: the sweep on a ``dask scheduler`` and ``--workers`` ``dask worker`` processes
   started by hand on this machine, a stand-in for a cluster of machines; the cluster is up
   before the clock starts, as an operator's would be (its start is recorded apart).

Per engine: the wall time; each unit's own time (measured inside the worker); the time until
the first unit starts (starting processes, importing torch, loading the data); the gaps
between one unit's end and the next unit's start on the same worker; the time from the last
unit's end to the results in hand; the wall time less the busiest worker's unit time, per
unit (the engine's overhead). And whether every cell and every prediction equals the pool's,
digit for digit. Writes results/sweep_engine.json.
"""
from __future__ import annotations

import contextlib
import os
import shutil
import socket
import statistics
import subprocess
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context
from pathlib import Path

import numpy as np
from harness import ROOT, Benchmark


def timed_unit(*unit) -> dict:
    """One Table 1 unit, with its start and end (wall clock) and the process that ran it."""
    from pgae_lite.runs.table1_unit import table1_unit

    start = time.time()
    result = table1_unit(*unit)
    return {**result, "start": start, "end": time.time(), "pid": os.getpid()}


def one_thread() -> None:
    import torch

    torch.set_num_threads(1)       # as a Dask worker's process (OMP_NUM_THREADS=1): one core each


def in_pool(units: list[tuple], workers: int) -> list[dict]:
    with ProcessPoolExecutor(workers, mp_context=get_context("spawn"), initializer=one_thread) as pool:
        return list(pool.map(timed_unit, *zip(*units)))


def in_sweep(units: list[tuple], workers: int, scheduler: str | None = None) -> list[dict]:
    from pgae_lite.runs.sweep import run_sweep

    return run_sweep(timed_unit, units, workers=workers, scheduler=scheduler, name="engine", progress=False)


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@contextlib.contextmanager
def separate_processes(workers: int):
    """A scheduler and ``workers`` workers started as separate commands, as on a lab's machines: its address."""
    address = f"tcp://127.0.0.1:{free_port()}"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), *sys.path])}
    procs = [subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1",
                               "--port", address.rsplit(":", 1)[1], "--dashboard-address", ":0"],
                              env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    try:
        time.sleep(3)
        procs += [subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_worker", address, "--nthreads", "1",
                                    "--no-dashboard"], env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                  for _ in range(workers)]
        from distributed import Client

        with Client(address) as client:
            client.wait_for_workers(workers, timeout=120)
        yield address
    finally:
        for p in procs:
            p.kill()
        for p in procs:
            p.wait(timeout=30)


def timing(done: list[dict], started: float, finished: float) -> dict:
    """The engine's figures from the units' own start and end times (seconds)."""
    by_worker: dict[int, list[dict]] = {}
    for u in sorted(done, key=lambda u: u["start"]):
        by_worker.setdefault(u["pid"], []).append(u)
    gaps = [b["start"] - a["end"] for units in by_worker.values() for a, b in zip(units, units[1:])]
    busiest = max(sum(u["end"] - u["start"] for u in units) for units in by_worker.values())
    return {"wall_s": finished - started,
            "unit_s": [u["end"] - u["start"] for u in done],
            "first_unit_start_s": min(u["start"] for u in done) - started,
            "gaps_between_units_s": gaps,
            "last_unit_to_results_s": finished - max(u["end"] for u in done),
            "workers_used": len(by_worker),
            "overhead_per_unit_s": (finished - started - busiest) / len(done)}


def same(a: list[dict], b: list[dict]) -> bool:
    """Every cell and every predicted word and joint value equal, unit by unit."""
    for x, y in zip(a, b):
        if x["cells"] != y["cells"]:
            return False
        for row, preds in x["predictions"].items():
            for signal, p in preds.items():
                q = y["predictions"][row][signal]
                if list(p.text) != list(q.text) or not np.array_equal(p.joints, q.joints, equal_nan=True):
                    return False
    return True


def main() -> None:
    bench = Benchmark("sweep_engine", __doc__, seeds=[0, 1, 2])
    bench.add_original_data()
    bench.parser.add_argument("--rows", default="PGAE")
    bench.add_workers(2, "units", sweep=False)
    bench.parser.add_argument("--runs", default="benchmarks/out/sweep_engine",
                              help="scratch folder (emptied before each engine runs)")
    args = bench.parse()
    from pgae_lite.config import get_profile
    from pgae_lite.runs.reproduce import parse_rows
    from pgae_lite.runs.rows import ROWS

    rows, profile = parse_rows(args.rows), get_profile(args.profile)
    source = str(Path(args.original_data).resolve())
    trainings = list({ROWS[r].training.name: ROWS[r].training for r in rows}.values())
    figures, results = {}, {}
    for name in ("pool", "local", "separate"):
        out = Path(args.runs).resolve() / name
        shutil.rmtree(out, ignore_errors=True)
        units = [(source, profile, t, seed, [ROWS[r] for r in rows if ROWS[r].training == t], str(out), "cpu", None)
                 for t in trainings for seed in args.seeds]
        # The hand-started cluster is started (and its start timed) before the sweep, as an operator would.
        up = time.time()
        with separate_processes(args.workers) if name == "separate" else contextlib.nullcontext() as scheduler:
            started = time.time()
            results[name] = (in_pool(units, args.workers) if name == "pool"
                             else in_sweep(units, args.workers, scheduler))
            figures[name] = timing(results[name], started, time.time()) | {"cluster_start_s": started - up}
        t = figures[name]
        print(f"{name:9s} wall {t['wall_s']:7.1f} s, units {statistics.median(t['unit_s']):6.1f} s (median), "
              f"first unit after {t['first_unit_start_s']:5.1f} s, overhead {t['overhead_per_unit_s']:5.2f} s per unit",
              flush=True)
    identical = {name: same(results["pool"], r) for name, r in results.items() if name != "pool"}
    print("cells and predictions identical to the pool's:", identical)
    cells = [{"training": u["training"], "seed": u["seed"], "cells": u["cells"]} for u in results["pool"]]
    bench.write({"rows": rows, "units": len(cells), "workers": args.workers, "engines": figures,
                 "identical_to_pool": identical, "cells": cells})


if __name__ == "__main__":
    main()
