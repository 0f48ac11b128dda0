"""The student edition: the book and its notebooks without the exercises' solutions (not in the paper).

The instructor edition is the repository itself. :func:`write_student_edition` writes a copy of the
book's sources into a new folder, from the same files (no chapter is kept twice): ``_config.yml`` with
sphinx-exercise's ``hide_solutions: true`` under ``sphinx.config``, ``_toc.yml``, the ``book/`` folder
(pages, local extensions, scripts, ``references.bib``) and every notebook as :func:`student_notebook`
makes it: in ``handout/`` without outputs, for students to run; in ``notebooks/``, the book's chapters,
with the outputs of an executed copy when one is given. ``python -m pgae_lite student-edition OUT
[--executed DIR] --build`` also builds it (``OUT/_build/html``).

A page for teachers only (notebook metadata ``"pgae": {"instructor_only": true}``, e.g. the page with the
problem sets' rubrics) is left out of the student edition, and out of its ``_toc.yml``.

Solutions are known in two forms: a ``{solution}`` directive in a markdown cell, as a MyST colon fence
(``:::{solution} label`` ... ``:::``, as the book writes them) or a backtick fence; and a whole cell tagged
``solution`` (a convention the book does not use today, removed if it ever does).
"""
from __future__ import annotations

import copy
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import yaml

from pgae_lite.util.checks import output_folder
from pgae_lite.util.errors import PGAELiteError

ROOT = Path(__file__).resolve().parents[2]
MARKER = ".student-edition"             # written first into OUT: a folder with it is one this module made
SOLUTION_TAG = "solution"
_FENCE = re.compile(r"^ {0,3}(:{3,}|`{3,}|~{3,})\s*(.*?)\s*$")


def strip_solutions(markdown: str) -> str:
    """``markdown`` without its ``{solution}`` directives, each removed whole with its fence.

    A directive ends where MyST ends it: at the first line of only the fence's character, at least as
    many as opened it (so code fences and shorter nested colon fences inside it stay inside it). A
    ``{solution}`` shown inside a code block is text, not a directive, and stays.
    """
    lines = markdown.splitlines(keepends=True)
    out: list[str] = []
    i = 0
    while i < len(lines):
        match = _FENCE.match(lines[i])
        if not match:
            out.append(lines[i])
            i += 1
            continue
        marker, info = match.groups()
        end = _closing(lines, i + 1, marker)
        if info.startswith("{solution}"):
            i = end + 1
            if i < len(lines) and not lines[i].strip() and (not out or not out[-1].strip()):
                i += 1                  # one blank line of the two around the block goes with it
            continue
        if marker[0] == ":":            # another directive: its content may hold solutions too
            out.append(lines[i])
            out.append(strip_solutions("".join(lines[i + 1:end])))
            out.extend(lines[end:end + 1])
        else:                           # a code block: its text stays as written
            out.extend(lines[i:end + 1])
        i = end + 1
    return "".join(out)


def _closing(lines: list[str], start: int, marker: str) -> int:
    """The index of the line that closes a fence opened with ``marker`` (len(lines) if none does)."""
    for j in range(start, len(lines)):
        match = _FENCE.match(lines[j])
        if match and not match.group(2) and match.group(1)[0] == marker[0] and len(match.group(1)) >= len(marker):
            return j
    return len(lines)


def student_notebook(nb: dict, keep_outputs: bool = False) -> dict:
    """A copy of notebook ``nb`` (nbformat 4 JSON) for students: solutions out of its markdown cells, cells
    tagged ``solution`` and markdown cells left empty removed, every output and execution count cleared
    (kept with ``keep_outputs``: the student book then shows what the chapter computed)."""
    nb = copy.deepcopy(nb)
    cells = []
    for cell in nb.get("cells", []):
        if SOLUTION_TAG in cell.get("metadata", {}).get("tags", []):
            continue
        if cell.get("cell_type") == "markdown":
            source = cell.get("source", "")
            text = strip_solutions(source if isinstance(source, str) else "".join(source))
            if not text.strip():
                continue
            cell["source"] = text.splitlines(keepends=True)
        elif cell.get("cell_type") == "code" and not keep_outputs:
            cell["outputs"], cell["execution_count"] = [], None
        cells.append(cell)
    nb["cells"] = cells
    return nb


def instructor_only(nb: dict) -> bool:
    """Whether notebook ``nb`` is a page for teachers only (left out of the student edition)."""
    return bool(nb.get("metadata", {}).get("pgae", {}).get("instructor_only"))


def student_toc(text: str, left_out: list[str]) -> str:
    """The book's ``_toc.yml`` (as text) without the entries of the pages ``left_out`` (paths without suffix)."""
    for page in left_out:
        text = re.sub(rf"(?m)^[ \t]*- file: {re.escape(page)}[ \t]*\n", "", text)
    return text


def student_config(text: str) -> str:
    """The book's ``_config.yml`` (as text) with ``hide_solutions: true`` under ``sphinx.config``: one
    line inserted, comments kept; written anew from its data only where a line cannot do it."""
    config = yaml.safe_load(text) or {}
    wanted = copy.deepcopy(config)
    sphinx = wanted["sphinx"] = wanted.get("sphinx") or {}
    sphinx["config"] = {**(sphinx.get("config") or {}), "hide_solutions": True}
    inserted = re.sub(r"(?m)^(sphinx:[^\n]*\n(?:(?:  [^\n]*|[ \t]*)\n)*?  config:[ \t]*\n)",
                      r"\1    hide_solutions: true   # the student edition: no solutions\n", text, count=1)
    if yaml.safe_load(inserted) == wanted:
        return inserted
    return yaml.safe_dump(wanted, sort_keys=False, allow_unicode=True)


def _check_out(out: str | os.PathLike, root: Path) -> Path:
    """``out`` resolved, once :func:`~pgae_lite.util.checks.output_folder` (every output folder's check) allows it:
    outside the repository, and new, empty or written by this module before."""
    try:
        return output_folder("the student edition's folder", out, "student-edition", marker=MARKER,
                             outside={"the repository": root})
    except PGAELiteError as e:            # this module's errors, as before: one line "error: ..." on the command line
        raise PGAELiteError(str(e)) from None


def _code(nb: dict) -> list[str]:
    return ["".join(c.get("source", "")) for c in nb.get("cells", []) if c.get("cell_type") == "code"]


def executed_chapter(path: Path, executed: Path) -> dict:
    """The chapter ``path`` as executed in the folder ``executed`` (same name, outputs in it), after checking
    that its code is the chapter's: an executed copy of an older chapter is refused in one sentence."""
    done = executed / path.name
    if not done.is_file():
        raise PGAELiteError(f"{executed} holds no executed {path.name}: execute every chapter into it first "
                            "(see the README: jupyter nbconvert --execute --output-dir ...)")
    nb = json.loads(done.read_text(encoding="utf-8"))
    if _code(nb) != _code(json.loads(path.read_text(encoding="utf-8"))):
        raise PGAELiteError(f"{done}'s code differs from the chapter's ({path}): it was executed from another "
                            "version; execute the current chapters again")
    return nb


def write_student_edition(out: Path, root: Path = ROOT, executed: Path | None = None) -> Path:
    """Write the student edition's sources into ``out`` and return it (resolved): a new or empty folder
    outside the repository ``root``, or one this function wrote before (its ``book/``, ``notebooks/``,
    ``handout/``, ``_config.yml`` and ``_toc.yml`` are then written again; its ``_build`` is kept).

    ``handout/`` holds the notebooks students get, without solutions or outputs. ``notebooks/`` holds the
    book's chapters, the same; with ``executed`` (a folder of the chapters executed, each under its own
    name) they keep its outputs, so the student book shows what each chapter computed."""
    root = Path(root).resolve()
    out = _check_out(out, root)
    every = sorted((root / "notebooks").glob("*.ipynb"))
    teachers = [p for p in every if instructor_only(json.loads(p.read_text(encoding="utf-8")))]
    chapters = [p for p in every if p not in teachers]
    shown = {path.name: executed_chapter(path, Path(executed)) for path in chapters} if executed else {}
    out.mkdir(parents=True, exist_ok=True)
    (out / MARKER).write_text("Written by `python -m pgae_lite student-edition`: the student edition of "
                              f"the book in {root}. Writing it again replaces these files.\n", encoding="utf-8")
    for folder in ("book", "notebooks", "handout"):
        shutil.rmtree(out / folder, ignore_errors=True)
    shutil.copytree(root / "book", out / "book", ignore=shutil.ignore_patterns("__pycache__", ".ipynb_checkpoints"))
    for folder in ("notebooks", "handout"):
        (out / folder).mkdir()
    for path in chapters:
        source = json.loads(path.read_text(encoding="utf-8"))
        for folder, nb in (("handout", student_notebook(source)),
                           ("notebooks", student_notebook(shown.get(path.name, source), keep_outputs=True))):
            (out / folder / path.name).write_text(json.dumps(nb, indent=1, ensure_ascii=False) + "\n",
                                                  encoding="utf-8")
    (out / "_toc.yml").write_text(student_toc((root / "_toc.yml").read_text(encoding="utf-8"),
                                              [f"notebooks/{p.stem}" for p in teachers]), encoding="utf-8")
    (out / "_config.yml").write_text(student_config((root / "_config.yml").read_text(encoding="utf-8")),
                                     encoding="utf-8")
    return out


def build_student_edition(out: Path) -> int:
    """Build the written edition in ``out`` into ``out/_build/html`` with execution off (as the tests build
    the book: a copy of its config, local extension folders made absolute); the build's exit status."""
    out = Path(out).resolve()
    config = yaml.safe_load((out / "_config.yml").read_text(encoding="utf-8"))
    config.setdefault("execute", {})["execute_notebooks"] = "off"
    extensions = config.get("sphinx", {}).get("local_extensions") or {}
    for name, path in extensions.items():
        extensions[name] = str(out / path)
    jupyter_book = Path(sys.executable).with_name("jupyter-book")
    command = str(jupyter_book) if jupyter_book.exists() else "jupyter-book"
    with tempfile.TemporaryDirectory(prefix="pgae-student-config.") as folder:
        path = Path(folder) / "_config.yml"
        path.write_text(yaml.safe_dump(config, sort_keys=False, allow_unicode=True), encoding="utf-8")
        return subprocess.run([command, "build", str(out), "--config", str(path)], env=os.environ).returncode
