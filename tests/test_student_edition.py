"""The student edition (pgae_lite.course.student_edition): the book's sources without solutions.

Fast: nothing is built here (``python -m pgae_lite student-edition OUT --build`` builds it).
"""
from __future__ import annotations

import json
import re
import shutil

import pytest
import yaml

from pgae_lite.course.student_edition import (
    MARKER,
    ROOT,
    instructor_only,
    strip_solutions,
    student_notebook,
    write_student_edition,
)
from pgae_lite.util.errors import PGAELiteError

NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))

SYNTHETIC = """Before.

:::{exercise} Count the cubes (★)
:label: ex-count

How many cubes?
:::

:::{solution} ex-count
:class: dropdown

```python
print(2)
:::{not-a-directive} inside code
```

Two cubes: THE-ANSWER-TEXT.
:::

After.

```markdown
:::{solution} shown-as-text
:::
```
"""


def markdown(nb: dict) -> str:
    return "\n".join("".join(c["source"]) for c in nb["cells"] if c["cell_type"] == "markdown")


def test_a_solution_with_code_and_text_is_removed_whole():
    stripped = strip_solutions(SYNTHETIC)
    assert "THE-ANSWER-TEXT" not in stripped and "print(2)" not in stripped and ":class: dropdown" not in stripped
    assert ":::{exercise} Count the cubes (★)\n:label: ex-count\n\nHow many cubes?\n:::\n" in stripped
    assert stripped.startswith("Before.") and "\nAfter.\n" in stripped
    assert ":::{solution} shown-as-text" in stripped          # inside a code block it is text, not a directive
    assert strip_solutions(stripped) == stripped


def test_a_longer_fence_with_a_nested_directive_is_removed_whole():
    text = "A\n\n::::{solution} ex\n:::{note}\nInner.\n:::\nStill the solution.\n::::\n\nB\n"
    assert strip_solutions(text) == "A\n\nB\n"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_every_notebook_loses_its_solutions_and_keeps_its_exercises(path):
    nb = json.loads(path.read_text(encoding="utf-8"))
    student = student_notebook(nb)
    before, after = markdown(nb), markdown(student)
    assert "{solution}" not in after
    exercises = re.findall(r"(?m)^:::\{exercise\}.*$", before)
    assert re.findall(r"(?m)^:::\{exercise\}.*$", after) == exercises
    assert [c["source"] for c in student["cells"] if c["cell_type"] == "code"] == \
           [c["source"] for c in nb["cells"] if c["cell_type"] == "code"
            and "solution" not in c.get("metadata", {}).get("tags", [])]     # the solutions' figures' code goes
    assert all(c["outputs"] == [] for c in student["cells"] if c["cell_type"] == "code")
    assert student_notebook(student) == student


def test_a_cell_tagged_solution_is_removed():
    nb = {"cells": [{"cell_type": "code", "metadata": {"tags": ["solution"]}, "source": "x = 1", "outputs": []},
                    {"cell_type": "code", "metadata": {}, "source": "y = 2", "outputs": [{"output_type": "x"}],
                     "execution_count": 3}]}
    assert student_notebook(nb)["cells"] == [{"cell_type": "code", "metadata": {}, "source": "y = 2",
                                              "outputs": [], "execution_count": None}]
    assert len(nb["cells"]) == 2                               # the original is untouched


def test_the_written_folder(tmp_path):
    out = write_student_edition(tmp_path / "student")
    original = yaml.safe_load((ROOT / "_config.yml").read_text(encoding="utf-8"))
    config = yaml.safe_load((out / "_config.yml").read_text(encoding="utf-8"))
    assert config["sphinx"]["config"].pop("hide_solutions") is True
    assert config == original
    teachers = [p for p in NOTEBOOKS if instructor_only(json.loads(p.read_text(encoding="utf-8")))]
    assert [p.stem for p in teachers] == ["A5_teaching"]        # the teachers' page, with the rubrics
    toc = yaml.safe_load((out / "_toc.yml").read_text(encoding="utf-8"))
    pages = [c["file"] for part in toc["parts"] for c in part["chapters"]]
    book = [c["file"] for part in yaml.safe_load((ROOT / "_toc.yml").read_text(encoding="utf-8"))["parts"]
            for c in part["chapters"]]
    assert pages == [p for p in book if p != "notebooks/A5_teaching"]
    assert (out / "book" / "references.bib").is_file() and (out / "book" / "_ext" / "live_models.py").is_file()
    assert sorted(p.name for p in (out / "notebooks").iterdir()) == [p.name for p in NOTEBOOKS if p not in teachers]
    assert not (out / "handout" / "A5_teaching.ipynb").exists()
    for path in (out / "notebooks").iterdir():
        assert "{solution}" not in path.read_text(encoding="utf-8")
    (out / "_build").mkdir()
    (out / "_build" / "kept").write_text("x")
    assert write_student_edition(out) == out                   # written again over its own folder
    assert (out / "_build" / "kept").read_text() == "x" and (out / MARKER).is_file()


def test_it_refuses_the_repository_and_a_folder_inside_it():
    for out in (ROOT, ROOT / "student", ROOT / "notebooks"):
        with pytest.raises(PGAELiteError, match="outside the repository"):
            write_student_edition(out)
    assert not (ROOT / "student").exists()


def test_it_refuses_a_foreign_non_empty_folder(tmp_path):
    (tmp_path / "notes.txt").write_text("mine")
    (tmp_path / "notebooks").mkdir()
    (tmp_path / "notebooks" / "01_simulator.ipynb").write_text("my own")
    with pytest.raises(PGAELiteError, match="did not make"):
        write_student_edition(tmp_path)
    assert sorted(p.relative_to(tmp_path).as_posix() for p in tmp_path.rglob("*")) == \
           ["notebooks", "notebooks/01_simulator.ipynb", "notes.txt"]
    assert (tmp_path / "notebooks" / "01_simulator.ipynb").read_text() == "my own"


def test_the_command_line_lists_it():
    from test_cli import run

    top = run("--help")
    assert top.returncode == 0 and "student-edition" in top.stdout
    sub = run("student-edition", "--help")
    assert sub.returncode == 0 and "OUT" in sub.stdout and "--build" in sub.stdout


def test_the_command_line_refuses_in_one_line(tmp_path):
    from test_cli import run

    r = run("student-edition", ROOT / "student")
    assert r.returncode == 2 and r.stderr.startswith("error: ") and len(r.stderr.strip().splitlines()) == 1
    assert not (ROOT / "student").exists()


def test_the_student_book_shows_an_executed_copys_outputs_and_the_handout_none(tmp_path):
    executed = tmp_path / "executed"
    executed.mkdir()
    for path in NOTEBOOKS:                                  # an executed copy: the same code, with an output
        nb = json.loads(path.read_text(encoding="utf-8"))
        code = next(c for c in nb["cells"] if c["cell_type"] == "code")
        code["outputs"] = [{"output_type": "stream", "name": "stdout", "text": ["computed\n"]}]
        (executed / path.name).write_text(json.dumps(nb), encoding="utf-8")
    out = write_student_edition(tmp_path / "student", executed=executed)
    for path in NOTEBOOKS:
        if instructor_only(json.loads(path.read_text(encoding="utf-8"))):
            assert not (out / "notebooks" / path.name).exists()          # the teachers' page: not there
            continue
        book = json.loads((out / "notebooks" / path.name).read_text(encoding="utf-8"))
        handout = json.loads((out / "handout" / path.name).read_text(encoding="utf-8"))
        assert any(c.get("outputs") for c in book["cells"]), path.name
        assert not any(c.get("outputs") for c in handout["cells"] if c["cell_type"] == "code"), path.name
        assert ":::{solution}" not in json.dumps(book) + json.dumps(handout), path.name


def test_an_executed_copy_of_other_code_or_a_missing_chapter_is_refused(tmp_path):
    executed = tmp_path / "executed"
    executed.mkdir()
    for path in NOTEBOOKS[1:]:
        nb = json.loads(path.read_text(encoding="utf-8"))
        next(c for c in nb["cells"] if c["cell_type"] == "code")["source"] = ["print('older')"]
        (executed / path.name).write_text(json.dumps(nb), encoding="utf-8")
    with pytest.raises(PGAELiteError, match=f"holds no executed {NOTEBOOKS[0].name}"):
        write_student_edition(tmp_path / "a", executed=executed)
    shutil.copy(NOTEBOOKS[0], executed / NOTEBOOKS[0].name)
    with pytest.raises(PGAELiteError, match="code differs from the chapter's"):
        write_student_edition(tmp_path / "b", executed=executed)
    assert not (tmp_path / "b").exists()                    # refused before anything is written
