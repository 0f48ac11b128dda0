"""``python -m pgae_lite course``: prepare a class's cache, hand out the assignments, grade a folder of them.

Not in the paper: a course built on it. The three steps a teacher types, each a function of this folder:

    python -m pgae_lite course prepare CLASS [--profile book]            # once: the cache students copy
    python -m pgae_lite course assign COURSE [NAME ...]                 # the notebooks to hand out, the autograders
    python -m pgae_lite course grade NAME SUBMISSIONS --course COURSE --report REPORT   # scores.csv, Gradescope

Arguments are checked before anything runs (the folders by :func:`~pgae_lite.util.checks.output_folder` and
:func:`~pgae_lite.util.checks.input_folder`, as every command's); a bad one gets a usage line and a message
(``__main__``).
"""
from __future__ import annotations

import argparse
import re

#: What ``course grade`` writes into its report folder: a folder holding only these is one it wrote.
GRADE_WRITES = ("scores.csv", "gradescope")


def add_parser(sub, profiles: tuple[str, ...]) -> None:
    """The ``course`` command and its three steps, on the main parser's subcommands ``sub`` (``profiles``:
    the profiles' names)."""
    course = sub.add_parser("course", help="prepare a class's cache, hand out problem sets and labs, grade them",
                            description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    steps = course.add_subparsers(dest="step", required=True)
    prep = steps.add_parser("prepare", help="execute every chapter once into a cache students copy",
                            description="Execute the book's chapters in order with PGAE_LITE_CACHE=OUT/cache: the "
                                        "recording, the CAE and the chapters' models, once for a class. The "
                                        "executed chapters go to OUT/executed (for student-edition --executed).")
    prep.add_argument("out", metavar="OUT", help="the folder for the cache and the executed chapters")
    prep.add_argument("--profile", choices=profiles, default=None,
                      help="the profile students will use (default: $PGAE_LITE_PROFILE, else 'book')")
    prep.add_argument("--chapters", nargs="+", metavar="NAME", default=None,
                      help="only these chapters (e.g. 01_simulator 03_cae), in the book's order (default: all)")
    assign = steps.add_parser("assign", help="write the notebooks to hand out and their autograders",
                              description="Run otter assign on the course's problem sets and labs (course/): "
                                          "OUT/handout/NAME.ipynb for students, OUT/autograder/NAME.zip to grade "
                                          "(keep it private), OUT/solutions/NAME.ipynb for the teacher.")
    assign.add_argument("out", metavar="OUT", help="a folder outside the repository (new, empty, or made by this)")
    assign.add_argument("names", nargs="*", metavar="NAME", help="only these assignments (default: all)")
    grade = steps.add_parser("grade", help="grade a folder of submitted notebooks into a score report",
                             description="Grade each STUDENT.ipynb (or STUDENT/NAME.ipynb) in SUBMISSIONS with the "
                                         "assignment's autograder, offline and without containers, each in a "
                                         "scratch folder with a time limit. Writes REPORT/scores.csv and "
                                         "REPORT/gradescope/STUDENT.json.")
    grade.add_argument("name", metavar="NAME", help="the assignment, e.g. ps3_model or lab1_concat")
    grade.add_argument("submissions", metavar="SUBMISSIONS", help="the folder of submitted notebooks")
    grade.add_argument("--course", metavar="OUT", required=True, help="the folder `course assign` wrote")
    grade.add_argument("--report", metavar="REPORT", required=True, help="the folder for the reports")
    grade.add_argument("--timeout", type=float, default=None,
                       help="seconds one submission may run before it is stopped (default 600)")


def run(args: argparse.Namespace) -> int:
    """Run the step ``args.step`` (arguments checked first)."""
    from pathlib import Path

    from pgae_lite.util.errors import ArgumentError

    if args.step == "prepare":
        from pgae_lite.course.prepare import prepare_course

        seconds = prepare_course(args.out, args.profile, args.chapters)
        out = Path(args.out).expanduser().resolve()
        print(f"prepared {len(seconds)} chapters in {sum(seconds.values()) / 60:.1f} min: students set "
              f"PGAE_LITE_CACHE={out / 'cache'} (or copy it to ~/.cache/pgae_lite)")
        return 0
    if args.step == "assign":
        from pgae_lite.course.assign import assign_course

        out = assign_course(args.out, args.names or None)
        print(f"course written to {out}: hand out {out / 'handout'}; keep {out / 'autograder'} private")
        return 0
    from pgae_lite.course.grade import TIMEOUT, grade_folder
    from pgae_lite.util.checks import input_folder, output_folder, positive_number

    if not re.fullmatch(r"[A-Za-z0-9][A-Za-z0-9_.-]*", args.name):
        raise ArgumentError(f"NAME {args.name!r} is not an assignment's name (letters, digits, '_', '-' and '.', "
                            "e.g. ps3_model); the names are those of the autograders `course assign` wrote")
    submissions = input_folder("SUBMISSIONS", args.submissions, "folder of submitted notebooks")
    course = input_folder("--course", args.course, "course folder (the one `course assign` wrote)")
    report = output_folder("--report", args.report, "course grade", written=GRADE_WRITES,
                           outside={"the submissions folder": submissions})
    timeout = TIMEOUT if args.timeout is None else positive_number("--timeout", args.timeout)
    autograder = course / "autograder" / f"{args.name}.zip"
    if not autograder.is_file():
        raise ArgumentError(f"no autograder for {args.name!r} at {autograder}; run python -m pgae_lite course "
                            f"assign {args.course} first")
    grades = grade_folder(args.name, submissions, autograder, report, timeout)
    print(f"{len(grades)} submissions graded: {report / 'scores.csv'}")
    return 0
