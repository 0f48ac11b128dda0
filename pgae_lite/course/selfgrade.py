"""The course grades itself: reference solutions, untouched handouts and wrong components through the grader.

Not in the paper: a course built on it. :func:`grade_course` hands the course out into a folder
(:func:`~pgae_lite.course.assign.assign_course`) and grades, per assignment, the submissions a class's
extremes would hand in:

- ``reference``: the teacher's solutions, which must score full marks;
- ``untouched``: the handout as given, which must score zero;
- for a lab, ``wrong-MISTAKE``: the solutions with the student's component replaced, at the end of the
  notebook, by one of the lab's deliberately wrong components (``WRONG`` of its module in
  :mod:`pgae_lite.course.labs`), whose report must contain the words the lab names for that mistake.

CI runs it (tests/test_course_grading.py) and prints the score reports; ``benchmarks/course_grading.py``
writes the same figures, with the grading times, to ``results/course_grading.json``.
"""
from __future__ import annotations

import json
import re
import shutil
import time
from pathlib import Path

from pgae_lite.course.assign import assign_course, masters
from pgae_lite.course.grade import TIMEOUT, grade_folder, questions
from pgae_lite.course.labs import LABS, lab


def lab_of(name: str) -> str | None:
    """The lab module behind assignment ``name`` (``lab1_concat`` -> ``concat``), or None for a problem set."""
    for module in LABS:
        if name.startswith("lab") and name.split("_", 1)[-1] == module:
            return module
    return None


def _with_cell(notebook: Path, code: str, to: Path) -> None:
    """A copy of ``notebook`` with one more code cell, ``code``, at its end."""
    nb = json.loads(notebook.read_text(encoding="utf-8"))
    nb["cells"].append({"cell_type": "code", "execution_count": None, "metadata": {}, "outputs": [],
                        "source": code})
    to.write_text(json.dumps(nb, indent=1) + "\n", encoding="utf-8")


def submissions(name: str, course: Path, folder: Path) -> dict[str, list[str]]:
    """Write the extremes' submissions of ``name`` into ``folder``; ``{student: words its report must have}``."""
    folder.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(course / "solutions" / f"{name}.ipynb", folder / "reference.ipynb")
    shutil.copyfile(course / "handout" / f"{name}.ipynb", folder / "untouched.ipynb")
    expected: dict[str, list[str]] = {"reference": [], "untouched": []}
    module = lab_of(name)
    if module is None:
        return expected
    for mistake, (_, words) in lab(module).WRONG.items():
        student = "wrong-" + re.sub(r"[^a-z0-9]+", "-", mistake.lower()).strip("-")   # a plain file name
        code = (f"from pgae_lite.course.labs.{module} import WRONG as _WRONG\n"
                f"{lab(module).STUDENT_NAME} = _WRONG[{mistake!r}][0]   # a deliberately wrong component\n")
        _with_cell(folder / "reference.ipynb", code, folder / f"{student}.ipynb")
        expected[student] = [words] if isinstance(words, str) else list(words)
    return expected


def grade_course(out: str | Path, names: list[str] | None = None, timeout: float = TIMEOUT,
                 progress: bool = False) -> dict:
    """Hand the course out into ``out`` and grade each assignment's extremes; what each scored and said."""
    out = Path(out)
    start = time.perf_counter()
    course = assign_course(out / "course", names)
    report: dict = {"assign_seconds": round(time.perf_counter() - start, 1), "assignments": {}}
    for name in names or list(masters()):
        expected = submissions(name, course, out / "submissions" / name)
        start = time.perf_counter()
        grades = grade_folder(name, out / "submissions" / name, course / "autograder" / f"{name}.zip",
                              out / "reports" / name, timeout, progress)
        seconds = time.perf_counter() - start
        possible = questions(course / "autograder" / f"{name}.zip")
        report["assignments"][name] = {
            "possible": sum(possible.values()), "questions": possible,
            "seconds_per_submission": round(seconds / len(grades), 1),
            "grades": {g.student: {"total": g.total, "status": g.status, "message": " | ".join(g.messages),
                                   "diagnosed": all(w in json.dumps(g.results, ensure_ascii=False)
                                                    for w in expected.get(g.student, []))}
                       for g in grades}}
    return report
