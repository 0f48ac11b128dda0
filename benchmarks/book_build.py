"""Time the whole book: `jupyter-book build .` executing every chapter, and the time of each.

    python benchmarks/book_build.py [--profile book] [--fresh-cache] [--keep-build]

Runs in a copy-free way on this checkout: the book's execution cache
(_build/.jupyter_cache) is cleared first, so every chapter really executes.
``--fresh-cache`` also points PGAE_LITE_CACHE at an empty folder, so the
chapters record the data and train the CAE and the models too (the "from an
empty cache" figure); without it, whatever ~/.cache/pgae_lite holds is reused.
Per-chapter times come from myst-nb's execution records (jupyter-cache).
Writes benchmarks/out/book_build-PROFILE.json.
"""
import argparse
import json
import os
import shutil
import subprocess
import tempfile
import time
from pathlib import Path

from jupyter_cache import get_cache

ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
ap.add_argument("--profile", default="book")
ap.add_argument("--fresh-cache", action="store_true", help="an empty PGAE_LITE_CACHE (data, CAE, models made anew)")
args = ap.parse_args()

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
report = {"profile": args.profile, "fresh_cache": args.fresh_cache, "exit_code": done.returncode,
          "build_seconds": seconds, "chapter_seconds": dict(sorted(chapters.items())),
          "load_average": os.getloadavg()[0], "threads": os.cpu_count()}
out = root / "benchmarks" / "out" / f"book_build-{args.profile}.json"
out.parent.mkdir(parents=True, exist_ok=True)
out.write_text(json.dumps(report, indent=1))
for name, s in report["chapter_seconds"].items():
    print(f"{name:24s} {s / 60 if s else float('nan'):6.1f} min")
print(f"{'whole build':24s} {seconds / 60:6.1f} min (exit {done.returncode}); written to {out}")
raise SystemExit(done.returncode)
