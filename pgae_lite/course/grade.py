"""Grade a folder of submitted notebooks offline: a score per student and question, whatever they handed in.

Not in the paper: a course built on it. Each submission is graded by otter-grader's ``otter run`` (no
container, no network) against the assignment's autograder (:mod:`pgae_lite.course.assign`), in a process
of its own that starts in a scratch folder of its own, with its home and temporary folders inside it:

- a notebook that raises gets the points of the tests it still passes, and the error in its message;
- one that runs longer than ``timeout`` seconds is stopped (its whole process group) and scores 0;
- one that deletes or changes files it was not given (another student's notebook, the autograder, the
  reports) is caught: every such file is put back from a copy taken before grading began, and its
  message names them.

The reports, written again after every submission (nothing graded is lost if grading is stopped)::

    REPORT/scores.csv                 a row per student: a column per question, total, possible, status, message
    REPORT/gradescope/STUDENT.json    Gradescope's results format (what otter writes), one per student

``python -m pgae_lite course grade NAME SUBMISSIONS --course OUT --report REPORT`` is the command.
"""
from __future__ import annotations

import csv
import hashlib
import io
import json
import os
import re
import runpy
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

from pgae_lite.util.errors import ArgumentError
from pgae_lite.util.storage import atomic_write_text

TIMEOUT = 600.0           # seconds a submission may run: a lab's training cells are not run when grading


@dataclass
class Grade:
    """One student's grade: points per question, and what went wrong, in words."""

    student: str
    points: dict[str, float]
    possible: dict[str, float]
    status: str = "graded"                   # graded | timed out | not graded
    messages: list[str] = field(default_factory=list)
    results: dict = field(default_factory=dict)  # the grader's results, in Gradescope's format

    @property
    def total(self) -> float:
        return sum(self.points.values())


def questions(autograder: Path) -> dict[str, float]:
    """``{question: points}`` from the autograder's test files (each ``tests/NAME.py`` an otter test)."""
    try:
        with zipfile.ZipFile(autograder) as z, tempfile.TemporaryDirectory() as tmp:
            names = sorted(n for n in z.namelist() if re.fullmatch(r"tests/[^/]+\.py", n))
            found = {}
            for name in names:
                z.extract(name, tmp)
                test = runpy.run_path(str(Path(tmp) / name)).get("test", {})
                points = test.get("points")
                found[test.get("name", Path(name).stem)] = float(sum(points) if isinstance(points, list)
                                                                  else points or 1)
    except (zipfile.BadZipFile, OSError) as e:
        raise ArgumentError(f"{autograder} is not an autograder zip ({e}); make one with "
                            "python -m pgae_lite course assign OUT") from None
    if not found:
        raise ArgumentError(f"{autograder} holds no tests (tests/*.py)")
    return found


def submissions(folder: Path, name: str) -> dict[str, Path]:
    """``{student: notebook}``: ``folder/STUDENT.ipynb``, or ``folder/STUDENT/NAME.ipynb`` (one folder each)."""
    if not folder.is_dir():
        raise ArgumentError(f"no folder of submissions at {folder}")
    found = {p.stem: p for p in sorted(folder.glob("*.ipynb"))}
    for sub in sorted(p for p in folder.iterdir() if p.is_dir() and not p.name.startswith(".")):
        notebooks = sorted(sub.glob("*.ipynb"))
        mine = [p for p in notebooks if p.stem == name] or notebooks
        if len(mine) == 1:
            found.setdefault(sub.name, mine[0])
    if not found:
        raise ArgumentError(f"{folder} holds no notebooks: put each student's as STUDENT.ipynb, or "
                            f"STUDENT/{name}.ipynb")
    return found


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


class Guard:
    """A copy of every file under ``roots``, to find and put back what a submission deleted or changed."""

    def __init__(self, roots: list[Path], backup: Path):
        self.files = {p: _digest(p) for root in roots for p in sorted(root.rglob("*")) if p.is_file()}
        self.backup = backup
        for i, path in enumerate(self.files):
            shutil.copy2(path, backup / str(i))

    def restore(self) -> list[Path]:
        """The files that were deleted or changed since the copy, each put back; empty when none was."""
        harmed = []
        for i, (path, digest) in enumerate(self.files.items()):
            if not path.is_file() or _digest(path) != digest:
                harmed.append(path)
                path.parent.mkdir(parents=True, exist_ok=True)
                shutil.copy2(self.backup / str(i), path)
        return harmed


def _failure(output: str) -> str:
    """The first line that says why a test failed: a check's ✗ line, else the exception."""
    lines = [line.strip() for line in output.splitlines()]
    for line in lines:
        if line.startswith("✗"):
            return line
    for line in reversed(lines):
        if re.match(r"[A-Za-z_.]*(Error|Exception)\b", line):
            return line
    return "a test failed"


def run_one(notebook: Path, autograder: Path, timeout: float = TIMEOUT) -> tuple[dict | None, str]:
    """``otter run`` on a copy of ``notebook`` in a scratch folder; (Gradescope results or None, problem)."""
    with tempfile.TemporaryDirectory(prefix="pgae-grade-") as tmp:
        work = Path(tmp)
        for sub in ("home", "tmp", "out", "submission"):
            (work / sub).mkdir()
        copy = work / "submission" / notebook.name
        shutil.copyfile(notebook, copy)
        shutil.copyfile(autograder, work / "autograder.zip")
        env = {**os.environ, "HOME": str(work / "home"), "TMPDIR": str(work / "tmp"),
               "PYTHONDONTWRITEBYTECODE": "1"}
        command = [sys.executable, "-m", "otter", "run", "--no-logo", "-a", str(work / "autograder.zip"),
                   "-o", str(work / "out"), str(copy)]
        process = subprocess.Popen(command, cwd=work / "submission", env=env, stdout=subprocess.PIPE,
                                   stderr=subprocess.STDOUT, start_new_session=True)
        try:
            log, _ = process.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            os.killpg(process.pid, signal.SIGKILL)       # the kernel and anything it started, too
            process.communicate()
            return None, f"stopped after {timeout:.0f} s: the notebook did not finish (an endless loop?)"
        finally:
            if process.poll() is None:
                os.killpg(process.pid, signal.SIGKILL)
        results = work / "out" / "results.json"
        if process.returncode != 0 or not results.is_file():
            text = log.decode("utf-8", "replace").strip().splitlines()
            return None, "could not be graded: " + (_failure("\n".join(text[-40:])) if text else "no output")
        try:
            return json.loads(results.read_text(encoding="utf-8")), ""
        except json.JSONDecodeError:
            return None, "could not be graded: the grader's results were not readable"


def grade_one(student: str, notebook: Path, autograder: Path, possible: dict[str, float],
              timeout: float = TIMEOUT) -> Grade:
    """One student's :class:`Grade`, their Gradescope results in it."""
    grade = Grade(student, {q: 0.0 for q in possible}, dict(possible))
    results, problem = run_one(notebook, autograder, timeout)
    if results is None:
        grade.status = "timed out" if problem.startswith("stopped") else "not graded"
        grade.messages.append(problem)
        tests = [{"name": q, "score": 0.0, "max_score": p, "output": problem} for q, p in possible.items()]
        grade.results = {"score": 0.0, "output": problem, "tests": tests}
        return grade
    grade.results = results
    for test in results.get("tests", []):
        name = test.get("name")
        if name in possible and test.get("score") is not None:
            grade.points[name] = float(test["score"])
            if grade.points[name] < possible[name]:
                grade.messages.append(f"{name}: {_failure(test.get('output', ''))}")
    return grade


def write_reports(grades: list[Grade], possible: dict[str, float], report: Path) -> Path:
    """``report/scores.csv`` (atomically): a row per student."""
    buffer = io.StringIO()
    writer = csv.writer(buffer)
    writer.writerow(["student", *possible, "total", "possible", "status", "message"])
    for g in grades:
        writer.writerow([g.student, *(f"{g.points[q]:g}" for q in possible), f"{g.total:g}",
                         f"{sum(possible.values()):g}", g.status, " | ".join(g.messages)])
    path = report / "scores.csv"
    atomic_write_text(path, buffer.getvalue())
    return path


def grade_folder(name: str, folder: str | os.PathLike, autograder: str | os.PathLike,
                 report: str | os.PathLike, timeout: float = TIMEOUT, progress: bool = True) -> list[Grade]:
    """Grade every submission of assignment ``name`` in ``folder``; the reports go to ``report``."""
    if not timeout > 0:
        raise ArgumentError(f"timeout must be a positive number of seconds; got {timeout!r}")
    folder, autograder = Path(folder).expanduser().resolve(), Path(autograder).expanduser().resolve()
    report = Path(report).expanduser().resolve()
    if report == folder or folder in report.parents:
        raise ArgumentError(f"write the report outside the submissions folder {folder}")
    possible = questions(autograder)
    work = submissions(folder, name)
    (report / "gradescope").mkdir(parents=True, exist_ok=True)
    grades: list[Grade] = []
    with tempfile.TemporaryDirectory(prefix="pgae-grade-backup-") as backup:
        guard = Guard([folder, autograder.parent], Path(backup))
        for student, notebook in work.items():
            start = time.perf_counter()
            grade = grade_one(student, notebook, autograder, possible, timeout)
            harmed = guard.restore()
            if harmed:
                grade.messages.append("changed or deleted files it was not given, put back: "
                                      + ", ".join(p.name for p in harmed))
            grades.append(grade)
            for g in grades:                  # all again after each: a stop, or a submission that
                atomic_write_text(report / "gradescope" / f"{g.student}.json",   # deleted them, loses nothing
                                  json.dumps(g.results, indent=1) + "\n")
            write_reports(grades, possible, report)
            if progress:
                print(f"{student}: {grade.total:g}/{sum(possible.values()):g} ({grade.status}, "
                      f"{time.perf_counter() - start:.0f} s)", flush=True)
    return grades
