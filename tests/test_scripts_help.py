"""Every benchmark and experiment script answers ``--help`` with its usage, and does nothing else.

A script whose ``--help`` fails (an import moved, an option spelled twice) would otherwise be found
only when someone next measures with it. Each runs in a process of its own, with an empty cache
folder that must stay empty.
"""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
SCRIPTS = sorted(p.relative_to(ROOT).as_posix() for folder in ("benchmarks", "experiments")
                 for p in (ROOT / folder).glob("*.py") if p.name != "harness.py")


def test_the_scripts_are_found():
    assert "benchmarks/table1.py" in SCRIPTS and "experiments/explore_recipe.py" in SCRIPTS


@pytest.mark.parametrize("script", SCRIPTS)
def test_help_prints_the_usage_and_writes_nothing(script, tmp_path):
    results = {p.name: p.stat().st_mtime_ns for p in (ROOT / "results").glob("*.json")}
    env = {**os.environ, "PGAE_LITE_CACHE": str(tmp_path / "cache"), "MPLBACKEND": "Agg"}
    done = subprocess.run([sys.executable, script, "--help"], cwd=ROOT, env=env, capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0, f"{script} --help failed:\n{done.stderr[-2000:]}"
    assert "usage:" in done.stdout, done.stdout[:500]
    assert not (tmp_path / "cache").exists() or not any((tmp_path / "cache").rglob("*")), "it wrote to the cache"
    assert {p.name: p.stat().st_mtime_ns for p in (ROOT / "results").glob("*.json")} == results
