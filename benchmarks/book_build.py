"""Time the whole book: `jupyter-book build .` executing every chapter, and the time of each.

    python benchmarks/book_build.py [--profile book] [--fresh-cache]

Runs in a copy-free way on this checkout: the book's execution cache
(_build/.jupyter_cache) is cleared first, so every chapter really executes.
``--fresh-cache`` also points PGAE_LITE_CACHE at an empty folder, so the
chapters record the data and train the CAE and the models too (the "from an
empty cache" figure); without it, whatever ~/.cache/pgae_lite holds is reused.
PGAE_ORIGINAL_DATA is removed from the build's environment unless
``--with-original-data`` is given (then appendix A1 trains on the authors' data).
Per-chapter times come from myst-nb's execution records (jupyter-cache), and so
do the tables the chapters print for their own models (the first Table 1 of
chapters 04-06, chapter 07's closed-loop summary), kept as the book shows them.
Writes results/book_build.json.
"""
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from harness import Benchmark
from jupyter_cache import get_cache

bench = Benchmark("book_build", __doc__)
bench.parser.add_argument("--fresh-cache", action="store_true",
                          help="an empty PGAE_LITE_CACHE (data, CAE, models made anew)")
bench.parser.add_argument("--with-original-data", action="store_true",
                          help="keep PGAE_ORIGINAL_DATA, so appendix A1 trains on the authors' data too "
                               "(default: the reader's build, without it)")
args = bench.parse()

root = Path(__file__).resolve().parent.parent
shutil.rmtree(root / "_build", ignore_errors=True)
env = dict(os.environ, PGAE_LITE_PROFILE=args.profile)
if not args.with_original_data:
    env.pop("PGAE_ORIGINAL_DATA", None)      # the book never depends on the authors' data
if args.fresh_cache:
    env["PGAE_LITE_CACHE"] = tempfile.mkdtemp(prefix="pgae-book-cache-")
t0 = time.perf_counter()
# this environment's jupyter-book (beside its python), whether or not it is on PATH
book_cli = shutil.which("jupyter-book", path=str(Path(sys.executable).parent)) or "jupyter-book"
done = subprocess.run([book_cli, "build", ".", "-W", "-n", "--keep-going"], cwd=root, env=env)
seconds = time.perf_counter() - t0

cache = get_cache(root / "_build" / ".jupyter_cache")
records = cache.list_cache_records()
chapters = {Path(r.uri).stem: r.data.get("execution_seconds") for r in records}


def printed(outputs) -> str:
    """What a code cell showed as text: its printed stream, else its result's text/plain."""
    text = "".join(o.get("text", "") for o in outputs if o.get("output_type") == "stream")
    shown = [o["data"]["text/plain"] for o in outputs if "text/plain" in o.get("data", {})]
    return text or "".join(shown)


# The chapters' own models as the built book shows them: the first Table 1 a chapter prints
# (format_table) and chapter 07's open/closed-loop summary (success_summary).
shown = {}
for r in records:
    for cell in cache.get_cache_bundle(r.pk).nb.cells:
        source = cell.source if cell.cell_type == "code" else ""
        if ("format_table(" in source or "success_summary(" in source) and cell.get("outputs"):
            shown.setdefault(Path(r.uri).stem, printed(cell.outputs))
report = {"fresh_cache": args.fresh_cache, "original_data_given": bool(env.get("PGAE_ORIGINAL_DATA")),
          "exit_code": done.returncode,
          "minutes": round(seconds / 60, 2),
          "chapter_minutes": {k: round(v / 60, 2) if v else None for k, v in sorted(chapters.items())},
          "load_average": os.getloadavg()[0], "chapter_tables": dict(sorted(shown.items()))}
for name, m in report["chapter_minutes"].items():
    print(f"{name:24s} {m if m is not None else float('nan'):6.1f} min")
print(f"{'whole build':24s} {seconds / 60:6.1f} min (exit {done.returncode})")
for name, text in report["chapter_tables"].items():
    print(f"\n{name}:\n{text}")
bench.write(report)
raise SystemExit(done.returncode)
