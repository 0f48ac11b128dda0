"""CI grades the course: every problem set and lab through the grader, as a class's extremes hand them in.

The reference solutions score full marks, the untouched handouts score zero, and each lab's deliberately
wrong components get the words that diagnose them (pgae_lite.course.selfgrade). With
``PGAE_COURSE_REPORT=DIR`` the score reports (DIR/reports/NAME/scores.csv) are kept there; .ci/test prints them.
"""
from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from pgae_lite.course.assign import masters
from pgae_lite.course.selfgrade import grade_course, lab_of

NAMES = list(masters())


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    out = Path(os.environ.get("PGAE_COURSE_REPORT") or tmp_path_factory.mktemp("course-grading"))
    graded = grade_course(out, timeout=600)
    (out / "grading.json").write_text(json.dumps(graded, indent=1) + "\n", encoding="utf-8")
    return graded


def test_the_course_has_a_problem_set_per_part_and_four_labs():
    assert sum(n.startswith("ps") for n in NAMES) == 6
    assert sum(lab_of(n) is not None for n in NAMES) == 4


@pytest.mark.parametrize("name", NAMES)
def test_reference_scores_full_marks_and_the_handout_zero(report, name):
    graded = report["assignments"][name]
    reference, untouched = graded["grades"]["reference"], graded["grades"]["untouched"]
    assert reference["total"] == graded["possible"] > 0, reference["message"]
    assert untouched["total"] == 0 and untouched["status"] == "graded", untouched["message"]


@pytest.mark.parametrize("name", [n for n in NAMES if lab_of(n)])
def test_each_wrong_component_of_a_lab_is_diagnosed(report, name):
    wrong = {s: g for s, g in report["assignments"][name]["grades"].items() if s.startswith("wrong-")}
    assert len(wrong) >= 2
    for student, grade in wrong.items():
        assert grade["total"] < report["assignments"][name]["possible"], student
        assert grade["diagnosed"], f"{student}: {grade['message']}"
