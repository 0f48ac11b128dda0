"""Prepare a class's cache once: every chapter executed, so that no student waits for a recording or a training.

Not in the paper: a course built on it. A student who opens chapter 04 first would wait for chapters
01-03's recording and CAE before the chapter's own training starts. :func:`prepare_course` executes the
book's chapters, in the book's order, with ``$PGAE_LITE_CACHE`` pointed at ``OUT/cache``: each chapter
caches exactly what it records and trains (the simulated episodes, the CAE and its features, the chapters'
models), so no list of models is kept here. Students copy ``OUT/cache`` to ``~/.cache/pgae_lite``, or
point ``PGAE_LITE_CACHE`` at a shared copy (read-only is fine once it is complete). The executed
chapters are kept in ``OUT/executed``: ``python -m pgae_lite student-edition BOOK --executed OUT/executed``
shows their outputs in the student's book.

``python -m pgae_lite course prepare OUT [--profile book] [--chapters 01_simulator ...]`` is the command.
"""
from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import yaml

from pgae_lite.util.checks import output_folder
from pgae_lite.util.errors import ArgumentError, PGAELiteError

ROOT = Path(__file__).resolve().parents[2]
TIMEOUT = 3600                              # seconds a chapter may run (the longest takes minutes)
WRITES = ("cache", "executed")              # what it writes into its folder: a folder holding only these is its own


class PrepareError(PGAELiteError):
    """A chapter failed while preparing the cache (its error is in the message)."""


def chapters(root: Path = ROOT) -> list[Path]:
    """The book's notebooks in the table of contents' order."""
    toc = yaml.safe_load((root / "_toc.yml").read_text(encoding="utf-8"))
    files = [c["file"] for part in toc.get("parts", []) for c in part.get("chapters", [])]
    return [root / f"{f}.ipynb" for f in files if (root / f"{f}.ipynb").is_file()]


def choose(names: list[str] | None, root: Path = ROOT) -> list[Path]:
    """The chapters called ``names`` (file names without .ipynb), in the book's order; all when none."""
    every = chapters(root)
    if not names:
        return every
    known = {p.stem: p for p in every}
    unknown = [n for n in names if n not in known]
    if unknown:
        raise ArgumentError(f"unknown chapter(s) {', '.join(map(repr, unknown))}; the chapters are: "
                            f"{', '.join(known)}")
    return [p for p in every if p.stem in names]


def prepare_course(out: str | os.PathLike, profile: str | None = None, names: list[str] | None = None,
                   progress: bool = True) -> dict[str, float]:
    """Execute the chosen chapters into ``out`` (see the module's docstring); seconds per chapter."""
    out = output_folder("the output folder", out, "course prepare", written=WRITES)
    todo = choose(names)
    cache, executed = out / "cache", out / "executed"
    executed.mkdir(parents=True, exist_ok=True)
    env = {**os.environ, "PGAE_LITE_CACHE": str(cache)}
    if profile:
        env["PGAE_LITE_PROFILE"] = profile
    seconds = {}
    for notebook in todo:
        start = time.perf_counter()
        done = subprocess.run([sys.executable, "-m", "jupyter", "nbconvert", "--to", "notebook", "--execute",
                               f"--ExecutePreprocessor.timeout={TIMEOUT}", "--output-dir", str(executed),
                               str(notebook)], cwd=notebook.parent, env=env, capture_output=True, text=True)
        if done.returncode != 0:
            raise PrepareError(f"{notebook.name} failed while preparing {cache}: "
                               + (done.stderr.strip().splitlines() or ["no output"])[-1])
        seconds[notebook.stem] = round(time.perf_counter() - start, 1)
        if progress:
            print(f"{notebook.stem}: {seconds[notebook.stem]:.0f} s", flush=True)
    return seconds
