"""Every exercise of the book has a solution, and no solution leaves its number to the reader's printout
(not in the paper; issue 61's point 5).

The exercises are MyST colon fences in the chapters' markdown cells, ``:::{exercise} Title`` with
``:label: ex-...``, each answered by ``:::{solution} ex-...``. A solution that asks for a figure gives it,
quoted from a committed result file or computed by a hidden cell of its chapter and glued into the text
(``{glue:text}`` / ``{glue:md}``); a phrase such as "read the printout" in a solution's prose, outside
its code, means the figure is missing. The book is built with warnings as errors, so every glue name a
solution uses must also be defined by a ``glue(...)`` call of the same notebook.
"""
from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

NOTEBOOKS = sorted((Path(__file__).resolve().parent.parent / "notebooks").glob("*.ipynb"))

#: prose by which the book's solutions have sent the reader to an output instead of giving its figure
DEFERRING = (
    "read the printout", "read the printed", "the printout gives", "the printout says", "compare the printed",
    "see the output", "look at the output", "read the output", "read the share", "read where the share",
    "read how many", "read the spread", "read the per-word columns", "read it from the", "read from the plot",
    "look whether it does", "the table shows", "the table says", "the table decides", "tables tell",
    "the two printed", "compare each line with", "compare every row with", "compare how clean",
    "no reference run", "no committed run", "is the measurement", "only a training", "your run is",
)

#: solutions whose figure needs a training or a measurement that no committed result file holds yet; each
#: names what would give it. An entry that no longer defers fails the test, so that it is taken off. The
#: trainings the others need are benchmarks/exercise_runs.py's (results/exercise_runs.json).
AWAITING_A_RESULT = {
    "ex-bert-model": "PGAE-BERT with bert-base-uncased needs the model's weights, which the machine that runs "
                     "benchmarks/exercise_runs.py cannot download (it has no access to the Hugging Face hub, and "
                     "no package on PyPI ships them); a reader who has the model runs the solution's code unchanged",
}

_FENCE = re.compile(r"^ {0,3}(:{3,})\s*(.*?)\s*$")
_CODE = re.compile(r"^ {0,3}(`{3,}|~{3,}).*?^ {0,3}\1[ \t]*$", re.M | re.S)
_GLUE_USED = re.compile(r"\{glue:(?:text|md|any|figure|math)?\}`([^`:]+)|^```\{glue\}\s+(\S+)", re.M)
_GLUE_DEFINED = re.compile(r"""\bglue\(\s*f?(["'])(.+?)\1""")


def directives(path: Path) -> list[tuple[str, str, str]]:
    """The notebook's exercises and solutions, in order: (kind, label, body), kind "exercise" or "solution"."""
    found = []
    for cell in json.loads(path.read_text(encoding="utf-8"))["cells"]:
        if cell["cell_type"] != "markdown":
            continue
        lines = "".join(cell["source"]).splitlines()
        for i, line in enumerate(lines):
            match = _FENCE.match(line)
            if not match or not match.group(2).startswith(("{exercise}", "{solution}")):
                continue
            marker, info = match.groups()
            end = next((j for j in range(i + 1, len(lines))
                        if (m := _FENCE.match(lines[j])) and not m.group(2) and len(m.group(1)) >= len(marker)),
                       len(lines))
            body = "\n".join(lines[i + 1:end])
            if info.startswith("{solution}"):
                found.append(("solution", info.removeprefix("{solution}").strip(), body))
            else:
                label = re.search(r"^:label:\s*(\S+)", body, re.M)
                found.append(("exercise", label.group(1) if label else f"(no label: {info})", body))
    return found


def prose(body: str) -> str:
    """A solution's text without its code blocks and options, lower case, on one line."""
    text = _CODE.sub(" ", body)
    text = re.sub(r"^:\w+:.*$", " ", text, flags=re.M)
    return " ".join(text.lower().split())


def glue_defined(path: Path) -> list[re.Pattern]:
    """The glue names the notebook's code defines, each as a pattern (an f-string's fields match anything)."""
    names = []
    for cell in json.loads(path.read_text(encoding="utf-8"))["cells"]:
        if cell["cell_type"] == "code":
            for _, name in _GLUE_DEFINED.findall("".join(cell["source"])):
                names.append(re.compile("".join(".+" if part.startswith("{") else re.escape(part)
                                                for part in re.split(r"(\{[^}]*\})", name)) + "$"))
    return names


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_every_exercise_has_a_solution(path):
    found = directives(path)
    exercises = [label for kind, label, _ in found if kind == "exercise"]
    solutions = [label for kind, label, _ in found if kind == "solution"]
    missing = [label for label in exercises if label not in solutions]
    assert not missing, f"{path.stem}: exercises without a solution: {', '.join(missing)}"
    orphans = [label for label in solutions if label not in exercises]
    assert not orphans, f"{path.stem}: solutions of no exercise in the chapter: {', '.join(orphans)}"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_no_solution_leaves_its_figure_to_the_printout(path):
    wrong, stale = [], []
    for kind, label, body in directives(path):
        if kind != "solution":
            continue
        text = prose(body)
        said = [phrase for phrase in DEFERRING if phrase in text]
        if said and label not in AWAITING_A_RESULT:
            wrong.append(f"{label} ({', '.join(repr(p) for p in said)})")
        if not said and label in AWAITING_A_RESULT:
            stale.append(label)
    assert not wrong, (f"{path.stem}: solutions that send the reader to an output instead of giving its figure: "
                       f"{'; '.join(wrong)}. Quote the figure from results/ or glue it from a hidden cell.")
    assert not stale, (f"{path.stem}: {', '.join(stale)} no longer defer(s) the figure: take it off "
                       "AWAITING_A_RESULT")


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_every_glue_a_solution_uses_is_defined_in_its_notebook(path):
    defined = glue_defined(path)
    undefined = sorted({name for kind, label, body in directives(path) if kind == "solution"
                        for name in (a or b for a, b in _GLUE_USED.findall(body))
                        if not any(p.match(name) for p in defined)})
    assert not undefined, (f"{path.stem}: solutions use glue names that no glue() call of the notebook defines: "
                           f"{', '.join(undefined)} (the book is built with warnings as errors)")


def test_the_deferring_phrases_are_found_in_prose_and_not_in_code():
    body = ":class: dropdown\n\n```python\nprint('read the printout')\n```\n\nThen Read the\nprintout.\n"
    assert prose(body) == "then read the printout."
    assert "read the printout" in prose(body)
    assert "read the printout" not in prose(body.replace("Then Read the\nprintout.", "It is 3."))


def test_every_exercise_run_is_quoted_in_its_solutions_chapter():
    """Each entry of results/exercise_runs.json (benchmarks/exercise_runs.py) is an exercise whose chapter reads it."""
    path = Path(__file__).resolve().parent.parent / "results" / "exercise_runs.json"
    if not path.is_file():
        pytest.skip("no results/exercise_runs.json")
    runs = json.loads(path.read_text(encoding="utf-8"))["data"]
    for label in runs:
        assert label not in AWAITING_A_RESULT, f"{label} has a committed run: take it off AWAITING_A_RESULT"
        chapters = [p for p in NOTEBOOKS if any(k == "solution" and lab == label for k, lab, _ in directives(p))]
        assert chapters, f"results/exercise_runs.json has {label!r}, which no chapter's solution answers"
        code = "".join("".join(c["source"]) for c in json.loads(chapters[0].read_text(encoding="utf-8"))["cells"]
                       if c["cell_type"] == "code")
        assert '"exercise_runs"' in code and f'"{label}"' in code, (
            f"{chapters[0].stem} does not read {label}'s run from results/exercise_runs.json")
