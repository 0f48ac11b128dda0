"""The one harness every benchmark uses: a common command line and one result format.

    from harness import Benchmark             # benchmarks/ is on sys.path when a script there runs

    def main() -> None:
        bench = Benchmark("table1", __doc__)  # --threads, --out, --profile, --seeds
        bench.parser.add_argument("--rows", default="PGAE")
        args = bench.parse()                  # sets torch's threads once, here
        ...
        bench.write({"rows": ...})            # results/table1.json (or --out)

    if __name__ == "__main__":
        main()

The work runs under the ``__main__`` guard: recording the simulated data
(:func:`pgae_lite.sim.dataset.generate`, which :func:`pgae_lite.runs.data.simulated_dataset`
and ``trained_cae`` call when the cache lacks it) and a sweep's local cluster
(:func:`side_by_side`) spawn worker processes, and each re-imports the script;
unguarded, they would run the benchmark again.

A result file is JSON::

    {"benchmark": "table1", "command": "python benchmarks/table1.py --seeds 0 1 2",
     "commit": "1a2b3c4 (+ uncommitted changes)", "date": "2026-11-24T15:02:11+00:00",
     "machine": {"cpu": "AMD EPYC", "cores": 2, "gpu": null, "torch": "2.13.0+cpu", "threads": 2},
     "profile": "book", "seeds": [0, 1, 2], "seconds": 1234.5, "data": {...}}

``data`` is whatever the benchmark measured; the book, the README and the
tests read every quoted figure from these files (:mod:`pgae_lite.runs.results`).
Files are written atomically, NaN refused (``allow_nan=False``): a result is
valid JSON or is not written.
"""
from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import shlex
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
DEFAULT_ORIGINAL_DATA = "../shared/pgae-original-data"
RESULTS = ROOT / "results"


def key_value(text: str) -> tuple[str, object]:
    """``KEY=VALUE`` from the command line: the key and its value (JSON where it parses, else the text)."""
    key, sep, raw = text.partition("=")
    if not sep or not key:
        raise argparse.ArgumentTypeError(f"expected KEY=VALUE, got {text!r}")
    try:
        return key, json.loads(raw)
    except json.JSONDecodeError:
        return key, raw


def commit() -> str:
    """The checkout's commit, marked when the tree has uncommitted changes (outside results/)."""
    def git(*a: str) -> str:
        return subprocess.run(["git", *a], cwd=ROOT, capture_output=True, text=True).stdout.strip()
    head = git("rev-parse", "--short", "HEAD") or "unknown"
    dirty = git("status", "--porcelain", "--untracked-files=no", "--", ".", ":!results")
    return head + (" (+ uncommitted changes)" if dirty else "")


def machine(threads: int | None = None) -> dict:
    """What the figures were measured on."""
    import torch

    cpu = platform.processor() or platform.machine()
    try:
        cpu = next(line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo") if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    gpu = torch.cuda.get_device_name(0) if torch.cuda.is_available() else None
    return {"cpu": cpu, "cores": os.cpu_count(), "gpu": gpu, "torch": torch.__version__,
            "threads": threads or torch.get_num_threads()}


class Benchmark:
    """Command line and result file of one benchmark named ``name``."""

    def __init__(self, name: str, doc: str | None = None, seeds: list[int] | None = None):
        self.name, self.t0 = name, time.perf_counter()
        self.commit = commit()      # the code measured: taken at the start, a later checkout cannot change it
        self.parser = argparse.ArgumentParser(description=doc,
                                              formatter_class=argparse.RawDescriptionHelpFormatter)
        self.parser.add_argument("--threads", type=int, default=None,
                                 help="torch threads per process (default: torch's, one per core)")
        self.parser.add_argument("--out", default=None, help=f"result file (default: results/{name}.json)")
        self.parser.add_argument("--profile", default=None,
                                 help="the recipe's profile: smoke, book or paper "
                                      "(default: $PGAE_LITE_PROFILE, else book)")
        self.parser.add_argument("--seeds", type=int, nargs="+", default=seeds or [0], help="seeds to run")
        self.args: argparse.Namespace | None = None

    def add_original_data(self, default: str | None = DEFAULT_ORIGINAL_DATA,
                          help: str = "the authors' data folder (holding target/ and vocabulary.txt)") -> None:
        """``--original-data PATH``, spelled as ``python -m pgae_lite reproduce`` spells it, in every script."""
        shown = f"default: $PGAE_ORIGINAL_DATA, else {default}" if default else "default: none"
        self.parser.add_argument("--original-data", metavar="PATH", help=f"{help} ({shown})",
                                 default=os.environ.get("PGAE_ORIGINAL_DATA", default) if default else None)

    def add_workers(self, default: int | None = 1, what: str = "runs", sweep: bool = True) -> None:
        """``--workers N``: how many ``what`` run at once on this machine (one spelling in every script);
        with ``sweep``, also ``--scheduler ADDRESS``: the benchmark's sweep (:func:`side_by_side`) on a
        Dask cluster instead of a local one."""
        self.parser.add_argument("--workers", type=int, default=default,
                                 help=f"{what} at once, in processes of their own "
                                      f"(default {default or 'one per core'})")
        if sweep:
            self.parser.add_argument("--scheduler", metavar="ADDRESS", default=None,
                                     help=f"run the {what} on the Dask cluster at ADDRESS (tcp://host:8786) "
                                          "instead of a local one (default: $PGAE_DASK_SCHEDULER, else local)")

    def parse(self, argv: list[str] | None = None) -> argparse.Namespace:
        self.args = self.parser.parse_args(argv)
        from pgae_lite.config import profile_name  # here, not at the top: --help stays fast
        from pgae_lite.util.errors import ArgumentError

        try:      # the name given, else $PGAE_LITE_PROFILE's, else book (checked: an unknown name fails here)
            self.args.profile = profile_name(self.args.profile)
        except ArgumentError as e:
            self.parser.error(str(e))
        if getattr(self.args, "scheduler", None):
            from pgae_lite.runs.sweep import SCHEDULER_ENV

            os.environ[SCHEDULER_ENV] = self.args.scheduler     # side_by_side's sweeps go there
        if self.args.threads:
            import torch

            torch.set_num_threads(self.args.threads)
            os.environ["OMP_NUM_THREADS"] = str(self.args.threads)   # for the processes it starts
        return self.args

    @property
    def path(self) -> Path:
        return Path(self.args.out) if self.args and self.args.out else RESULTS / f"{self.name}.json"

    def write(self, data: dict, **fields) -> Path:
        """``data`` with the command, commit, date and machine, to :attr:`path` (atomically)."""
        from pgae_lite.util.storage import atomic_write_text  # here: torch loads only when a result is written

        args = self.args or argparse.Namespace(profile=None, seeds=None, threads=None)
        report = {"benchmark": self.name,
                  "command": " ".join(["python", shlex.quote(os.path.relpath(sys.argv[0], ROOT))]
                                      + [shlex.quote(a) for a in sys.argv[1:]]),
                  "commit": self.commit,
                  "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
                  "machine": machine(args.threads), "profile": args.profile, "seeds": args.seeds,
                  "seconds": round(time.perf_counter() - self.t0, 1), **fields, "data": data}
        path = self.path
        path.parent.mkdir(parents=True, exist_ok=True)
        atomic_write_text(path, json.dumps(report, indent=1, allow_nan=False) + "\n")
        print(f"written to {os.path.relpath(path)}")
        return path


def side_by_side(work, jobs: list[tuple], workers: int) -> list:
    """``work(*job)`` for each job, in the jobs' order: each job a unit of one sweep on Dask
    (:func:`pgae_lite.runs.sweep.run_sweep`), on a local cluster of ``workers`` single-threaded
    processes, or on the cluster at ``--scheduler`` / ``$PGAE_DASK_SCHEDULER``.

    ``work`` must be a module-level function of the benchmark (the workers receive it pickled) and
    should set its own threads (one per worker: these networks gain nothing from two).
    """
    from pgae_lite.runs.sweep import run_sweep  # here: dask loads only when a sweep runs

    return run_sweep(work, jobs, workers=max(1, workers))
