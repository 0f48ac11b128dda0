"""Time the whole book: `jupyter-book build .` executing every chapter, and the time of each.

    python benchmarks/book_build.py [--profile book] [--fresh-cache]

Runs in a copy-free way on this checkout: the book's execution cache
(_build/.jupyter_cache) is cleared first, so every chapter really executes.
``--fresh-cache`` also points PGAE_LITE_CACHE at an empty folder, so the
chapters record the data and train the CAE and the models too (the "from an
empty cache" figure); without it, whatever ~/.cache/pgae_lite holds is reused.
Per-chapter times come from myst-nb's execution records (jupyter-cache).
Writes results/book_build.json.
"""
import os
import shutil
import subprocess
import tempfile
import time
from pathlib import Path

from jupyter_cache import get_cache

from harness import Benchmark

bench = Benchmark("book_build", __doc__)
bench.parser.add_argument("--fresh-cache", action="store_true",
                          help="an empty PGAE_LITE_CACHE (data, CAE, models made anew)")
args = bench.parse()

root = Path(__file__).resolve().parent.parent
shutil.rmtree(root / "_build", ignore_errors=True)
env = dict(os.environ, PGAE_LITE_PROFILE=args.profile)
if args.fresh_cache:
    env["PGAE_LITE_CACHE"] = tempfile.mkdtemp(prefix="pgae-book-cache-")
t0 = time.perf_counter()
done = subprocess.run(["jupyter-book", "build", ".", "-W", "-n", "--keep-going"], cwd=root, env=env)
seconds = time.perf_counter() - t0

chapters = {Path(r.uri).stem: r.data.get("execution_seconds")
            for r in get_cache(root / "_build" / ".jupyter_cache").list_cache_records()}
report = {"fresh_cache": args.fresh_cache, "exit_code": done.returncode,
          "minutes": round(seconds / 60, 2),
          "chapter_minutes": {k: round(v / 60, 2) if v else None for k, v in sorted(chapters.items())},
          "load_average": os.getloadavg()[0]}
for name, m in report["chapter_minutes"].items():
    print(f"{name:24s} {m if m is not None else float('nan'):6.1f} min")
print(f"{'whole build':24s} {seconds / 60:6.1f} min (exit {done.returncode})")
bench.write(report)
raise SystemExit(done.returncode)
