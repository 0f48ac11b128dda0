"""The course graded as CI grades it, timed: what a teacher's laptop spends per submission.

    python benchmarks/course_grading.py [--names ps1_world lab1_concat ...] [--profile book]

Hands the course out into a scratch folder and grades, per problem set and lab, the reference solutions,
the untouched handout and each lab's deliberately wrong components (pgae_lite.course.selfgrade), each
submission in its own process as ``python -m pgae_lite course grade`` runs it. Writes every score, status
and message, and the seconds per submission (executing the notebook and its tests: a lab's training cells
are not run when grading), to results/course_grading.json; the instructor's page quotes it.
"""
from __future__ import annotations

import tempfile

from harness import Benchmark

from pgae_lite.course.selfgrade import grade_course


def main() -> None:
    bench = Benchmark("course_grading", __doc__)
    bench.parser.add_argument("--names", nargs="+", default=None, help="only these assignments (default: all)")
    args = bench.parse()
    with tempfile.TemporaryDirectory(prefix="pgae-course-bench-") as out:
        bench.write(grade_course(out, args.names, progress=True))


if __name__ == "__main__":
    main()
