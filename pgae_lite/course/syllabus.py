"""What the course holds, read from its master notebooks: questions, points, checks and rubrics.

Not in the paper: a course built on it. The instructor's page (chapter A5) shows, per problem set and lab,
its questions, their points, the checks their tests call and, for an open question (``manual: true``, graded
by hand), the reference answer and rubric written in the master's solution cell. All of it is read here
from the masters in ``course/`` (otter's format: a raw ``# BEGIN QUESTION`` cell with the question's
settings, raw ``# BEGIN SOLUTION`` / ``# BEGIN TESTS`` cells around the solution and the tests), so the
page cannot drift from what the students get.
"""
from __future__ import annotations

import json
import re
from dataclasses import dataclass, field
from pathlib import Path

import yaml

from pgae_lite.course.assign import COURSE, masters

_CHECK = re.compile(r"\b(check(?:_\w+)?)\(")


@dataclass
class Question:
    """One question of an assignment, as its master states it."""

    name: str
    points: float
    manual: bool
    prompt: str = ""
    checks: list[str] = field(default_factory=list)     # the check functions its tests call
    hidden: int = 0                                     # how many of its tests the student does not see
    public: int = 0
    answer: str = ""                                    # a manual question's reference answer and rubric


def _text(cell: dict) -> str:
    source = cell.get("source", "")
    return source if isinstance(source, str) else "".join(source)


def questions(master: Path) -> list[Question]:
    """The questions of the master notebook ``master``, in order."""
    cells = json.loads(master.read_text(encoding="utf-8"))["cells"]
    found: list[Question] = []
    where = None                                          # None, "prompt", "solution" or "tests"
    for cell in cells:
        text = _text(cell).strip()
        if cell["cell_type"] == "raw":
            head = text.splitlines()[0].strip() if text else ""
            if head == "# BEGIN QUESTION":
                config = yaml.safe_load("\n".join(text.splitlines()[1:])) or {}
                found.append(Question(str(config.get("name")), float(config.get("points") or 0),
                                      bool(config.get("manual", False))))
                where = "prompt"
            elif head in ("# BEGIN SOLUTION", "# BEGIN TESTS"):
                where = head.split()[-1].lower()
            elif head in ("# END SOLUTION", "# END TESTS"):
                where = "prompt"
            elif head == "# END QUESTION":
                where = None
            continue
        if where is None or not found:
            continue
        question = found[-1]
        if where == "prompt" and cell["cell_type"] == "markdown" and not question.prompt:
            question.prompt = text
        elif where == "solution" and cell["cell_type"] == "markdown":
            question.answer = (question.answer + "\n\n" + text).strip()
        elif where == "tests" and cell["cell_type"] == "code":
            hidden = "hidden: true" in text
            question.hidden += hidden
            question.public += not hidden
            question.checks += [c for c in _CHECK.findall(text) if c not in question.checks]
    return found


def title(master: Path) -> str:
    """The master's first heading."""
    for cell in json.loads(master.read_text(encoding="utf-8"))["cells"]:
        if cell["cell_type"] == "markdown":
            for line in _text(cell).splitlines():
                if line.startswith("#"):
                    return line.lstrip("#").strip()
    return master.stem


def syllabus(course: Path = COURSE) -> dict[str, dict]:
    """``{assignment: {"title", "kind", "questions"}}`` for every master of the course, in order."""
    return {name: {"title": title(path), "kind": path.parent.name, "questions": questions(path)}
            for name, path in masters(course).items()}
