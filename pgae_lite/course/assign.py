"""Hand out the course: the problem sets and labs as the student's notebooks and the teacher's autograders.

Not in the paper: a course built on it. The sources are otter-grader master notebooks (otter's "v1"
format: questions, solutions and tests in one notebook) in ``course/problem_sets`` and ``course/labs``.
:func:`assign_course` runs ``otter assign`` on each, which checks that the solutions pass their own tests,
and lays the output out for a class::

    OUT/handout/NAME.ipynb          the notebook a student edits (public tests inside; no solutions)
    OUT/autograder/NAME.zip         what grades it (all tests, hidden ones included): keep it private
    OUT/solutions/NAME.ipynb        the master with its solutions, for the teacher

``python -m pgae_lite course assign OUT [NAME ...]`` is the command.
"""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from pgae_lite.util.checks import output_folder
from pgae_lite.util.errors import ArgumentError, PGAELiteError

ROOT = Path(__file__).resolve().parents[2]
COURSE = ROOT / "course"
FOLDERS = ("problem_sets", "labs")          # the masters, in the order a course takes them
MARKER = ".pgae-course"                      # written first into OUT: a folder with it is one this module made


class AssignError(PGAELiteError):
    """``otter assign`` refused a master notebook (its output says why)."""


def masters(course: Path = COURSE) -> dict[str, Path]:
    """Every master notebook of the course: ``{name: path}``, problem sets first, then labs."""
    found = {}
    for folder in FOLDERS:
        for path in sorted((course / folder).glob("*.ipynb")):
            found[path.stem] = path
    if not found:
        raise ArgumentError(f"no master notebooks in {course}/{{{','.join(FOLDERS)}}}: is this a checkout "
                            "of the project?")
    return found


def choose(names: list[str] | None, course: Path = COURSE) -> dict[str, Path]:
    """The masters called ``names`` (all when none is given); an unknown name lists the known ones."""
    every = masters(course)
    if not names:
        return every
    unknown = [n for n in names if n not in every]
    if unknown:
        raise ArgumentError(f"unknown assignment(s) {', '.join(map(repr, unknown))}; the course has: "
                            f"{', '.join(every)}")
    return {n: every[n] for n in names}


def check_out(out: str | os.PathLike) -> Path:
    """``out``, resolved, once known to be a folder this module may write into: new, empty, or one it made
    (:func:`~pgae_lite.util.checks.output_folder`, the check of every output folder)."""
    return output_folder("the output folder", out, "course assign", marker=MARKER, outside={"the repository": ROOT})


def prepare_out(out: str | os.PathLike) -> Path:
    """``out`` made ready to write into (see :func:`check_out`), marked as this module's."""
    out = check_out(out)
    out.mkdir(parents=True, exist_ok=True)
    (out / MARKER).write_text("made by python -m pgae_lite course assign\n", encoding="utf-8")
    return out


def assign_one(name: str, master: Path, out: Path, run_tests: bool = True) -> dict[str, Path]:
    """``otter assign`` on ``master``; its three outputs moved into ``out`` under ``name``."""
    with tempfile.TemporaryDirectory(prefix=f"pgae-assign-{name}-") as tmp:
        dist = Path(tmp) / "dist"
        command = [sys.executable, "-m", "otter", "assign", str(master), str(dist)]
        if not run_tests:
            command.append("--no-run-tests")
        done = subprocess.run(command, cwd=tmp, capture_output=True, text=True)
        zips = sorted((dist / "autograder").glob("*.zip"))
        if done.returncode != 0 or not zips:
            tail = (done.stdout + done.stderr)[-3000:]
            raise AssignError(f"otter assign refused {master.name} (exit {done.returncode}):\n{tail}")
        paths = {"handout": out / "handout" / f"{name}.ipynb", "autograder": out / "autograder" / f"{name}.zip",
                 "solutions": out / "solutions" / f"{name}.ipynb"}
        for path in paths.values():
            path.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(dist / "student" / master.name, paths["handout"])
        shutil.copyfile(zips[-1], paths["autograder"])
        shutil.copyfile(dist / "autograder" / master.name, paths["solutions"])
    return paths


def assign_course(out: str | os.PathLike, names: list[str] | None = None, run_tests: bool = True,
                  course: Path = COURSE) -> Path:
    """Every chosen master assigned into ``out`` (see the module's docstring); ``out`` returned."""
    check_out(out)
    chosen = choose(names, course)
    out = prepare_out(out)
    made = {name: {k: str(p.relative_to(out)) for k, p in assign_one(name, path, out, run_tests).items()}
            for name, path in chosen.items()}
    index = out / "course.json"
    known = json.loads(index.read_text(encoding="utf-8")) if index.exists() else {}
    index.write_text(json.dumps({**known, **made}, indent=1) + "\n", encoding="utf-8")
    return out
