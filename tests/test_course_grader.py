"""Handing out and grading (pgae_lite.course.assign, pgae_lite.course.grade) on a one-question course.

The course here is written by the test (a master notebook in otter's format with a public and a hidden
test), so these tests say what the grader does whatever the course's own problem sets hold: full marks for
the solutions, zero for the handout, and a score and a message, harming nothing else, for a submission
that crashes, loops, deletes files or is not a notebook. tests/test_course_grading.py grades the course's
own assignments.
"""
from __future__ import annotations

import csv
import json
import shutil

import nbformat
import pytest

from pgae_lite.__main__ import main
from pgae_lite.course.assign import MARKER, assign_course, check_out, choose
from pgae_lite.course.grade import grade_folder, questions, submissions
from pgae_lite.util.errors import ArgumentError

CELLS = [("raw", "# ASSIGNMENT CONFIG\nname: tiny\nexport_cell: false\ngenerate:\n  pdf: false"),
         ("markdown", "# A tiny problem set"),
         ("raw", "# BEGIN QUESTION\nname: q1\npoints: 3"),
         ("markdown", "Write the GMU of the paper's Sec. 3."),
         ("raw", "# BEGIN SOLUTION"),
         ("code", "from pgae_lite.model.layers import GatedMultimodalUnit\nMyGMU = GatedMultimodalUnit  # SOLUTION"),
         ("raw", "# END SOLUTION"),
         ("raw", "# BEGIN TESTS"),
         ("code", "from pgae_lite.exercises import check_gmu\nresult = check_gmu(MyGMU)\nassert result, str(result)"),
         ("code", '""" # BEGIN TEST CONFIG\nhidden: true\n""" # END TEST CONFIG\n'
                  "from pgae_lite.exercises import check_gmu\nresult = check_gmu(MyGMU, seed=5)\n"
                  "assert result, str(result)"),
         ("raw", "# END TESTS"),
         ("raw", "# END QUESTION")]


@pytest.fixture(scope="module")
def course(tmp_path_factory):
    """The tiny course, handed out: (OUT, the folder of its sources)."""
    source = tmp_path_factory.mktemp("source")
    (source / "problem_sets").mkdir()
    nb = nbformat.v4.new_notebook()
    make = {"raw": nbformat.v4.new_raw_cell, "markdown": nbformat.v4.new_markdown_cell,
            "code": nbformat.v4.new_code_cell}
    nb.cells = [make[kind](text) for kind, text in CELLS]
    nb.metadata["kernelspec"] = {"display_name": "Python 3", "language": "python", "name": "python3"}
    nbformat.write(nb, source / "problem_sets" / "tiny.ipynb")
    return assign_course(tmp_path_factory.mktemp("course") / "out", course=source), source


def _variant(course, folder, student: str, code: str) -> None:
    """The solutions with one more cell, ``code``, after the first."""
    nb = json.loads((course / "solutions" / "tiny.ipynb").read_text(encoding="utf-8"))
    nb["cells"].insert(1, {"cell_type": "code", "execution_count": None, "metadata": {}, "outputs": [],
                           "source": code})
    (folder / f"{student}.ipynb").write_text(json.dumps(nb), encoding="utf-8")


def test_assign_lays_the_course_out_and_keeps_solutions_and_hidden_tests_from_the_handout(course):
    out, _ = course
    assert (out / MARKER).exists() and json.loads((out / "course.json").read_text())["tiny"]
    handout = (out / "handout" / "tiny.ipynb").read_text(encoding="utf-8")
    assert "GatedMultimodalUnit  #" not in handout and "seed=5" not in handout     # no solution, no hidden test
    assert "check_gmu(MyGMU)" in handout                                              # the public test is there
    assert questions(out / "autograder" / "tiny.zip") == {"q1": 3.0}


def test_hostile_submissions_get_a_score_and_a_message_and_harm_nothing(course, tmp_path):
    out, _ = course
    subs = tmp_path / "submissions"
    subs.mkdir()
    shutil.copyfile(out / "solutions" / "tiny.ipynb", subs / "ref.ipynb")
    (subs / "untouched").mkdir()                                   # a folder per student works too
    shutil.copyfile(out / "handout" / "tiny.ipynb", subs / "untouched" / "tiny.ipynb")
    _variant(out, subs, "crash", 'raise RuntimeError("boom")')
    _variant(out, subs, "loop", "while True:\n    pass")
    _variant(out, subs, "deleter", f"import glob, os\nfor p in glob.glob({str(subs)!r} + '/*.ipynb'):\n"
                                   f"    os.remove(p)\nos.remove({str(out / 'autograder' / 'tiny.zip')!r})")
    (subs / "broken.ipynb").write_text("{not a notebook", encoding="utf-8")
    before = {p.name: p.read_bytes() for p in subs.glob("*.ipynb")}
    report = tmp_path / "report"
    grades = {g.student: g for g in grade_folder("tiny", subs, out / "autograder" / "tiny.zip", report,
                                                  timeout=45, progress=False)}
    assert grades["ref"].total == 3 and grades["ref"].status == "graded"
    assert grades["untouched"].total == 0 and "ellipsis" in grades["untouched"].messages[0]
    assert grades["crash"].total == 3                         # an unrelated error costs nothing
    assert grades["loop"].total == 0 and grades["loop"].status == "timed out"
    assert grades["broken"].status == "not graded" and "JSON" in grades["broken"].messages[0]
    assert grades["deleter"].total == 3 and "put back" in grades["deleter"].messages[-1]
    assert {p.name: p.read_bytes() for p in subs.glob("*.ipynb")} == before        # nothing lost
    assert (out / "autograder" / "tiny.zip").is_file()
    rows = {r["student"]: r for r in csv.DictReader((report / "scores.csv").open(encoding="utf-8"))}
    assert set(rows) == set(grades) and rows["ref"]["q1"] == "3" and rows["ref"]["possible"] == "3"
    gradescope = json.loads((report / "gradescope" / "ref.json").read_text(encoding="utf-8"))
    assert sum(t.get("score") or 0 for t in gradescope["tests"]) == 3


def test_bad_arguments_say_what_is_allowed(course, tmp_path):
    out, source = course
    with pytest.raises(ArgumentError, match="empty text"):
        check_out("  ")
    with pytest.raises(ArgumentError, match="inside the repository"):
        check_out(__file__)
    (tmp_path / "full").mkdir()
    (tmp_path / "full" / "mine.txt").write_text("keep me")
    with pytest.raises(ArgumentError, match="did not write"):
        assign_course(tmp_path / "full", course=source)
    assert (tmp_path / "full" / "mine.txt").read_text() == "keep me"
    with pytest.raises(ArgumentError, match="the course has: tiny"):
        choose(["nope"], source)
    with pytest.raises(ArgumentError, match="holds no notebooks"):
        submissions(tmp_path, "tiny")
    with pytest.raises(ArgumentError, match="not an autograder"):
        questions(out / "handout" / "tiny.ipynb")
    with pytest.raises(ArgumentError, match="timeout"):
        grade_folder("tiny", tmp_path, out / "autograder" / "tiny.zip", tmp_path / "r", timeout=0)
    with pytest.raises(SystemExit):                                 # the command line: a usage line and a message
        main(["course", "grade", "tiny", str(tmp_path), "--course", str(tmp_path / "none"), "--report",
              str(tmp_path / "r")])


def test_prepare_executes_the_chapters_into_a_cache_of_their_own(tmp_path, monkeypatch):
    from pgae_lite.course.prepare import chapters, prepare_course

    monkeypatch.setenv("PGAE_LITE_PROFILE", "smoke")
    assert [p.stem for p in chapters()][:2] == ["01_simulator", "02_dataset"]       # the book's order
    seconds = prepare_course(tmp_path / "class", names=["02_dataset"], progress=False)
    assert list(seconds) == ["02_dataset"]
    executed = json.loads((tmp_path / "class" / "executed" / "02_dataset.ipynb").read_text(encoding="utf-8"))
    assert any(c.get("outputs") for c in executed["cells"] if c["cell_type"] == "code")
    assert any((tmp_path / "class" / "cache").rglob("*"))                 # what the chapter recorded, there
    with pytest.raises(ArgumentError, match="the chapters are: 01_simulator"):
        prepare_course(tmp_path / "class", names=["02_datset"])
    with pytest.raises(ArgumentError, match="empty text"):
        prepare_course(" ")
