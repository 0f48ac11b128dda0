"""Notebooks are committed without outputs.

CI executes every notebook itself (nbmake, smoke profile) and the book is
built from those fresh outputs, so outputs saved in the repository would
only be stale, large and noisy in diffs. `.ci/test` runs this check before
it executes anything. To clear a notebook: Jupyter's "Clear All Outputs",
or `jupyter nbconvert --clear-output --inplace notebooks/NAME.ipynb`.
"""

import json
from pathlib import Path

import pytest

NOTEBOOKS = sorted((Path(__file__).resolve().parent.parent / "notebooks").glob("*.ipynb"))


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.name for p in NOTEBOOKS])
def test_notebook_has_no_outputs(path):
    notebook = json.loads(path.read_text(encoding="utf-8"))
    cells = notebook["cells"]
    dirty = [
        i
        for i, cell in enumerate(cells)
        if cell["cell_type"] == "code" and (cell.get("outputs") or cell.get("execution_count") is not None)
    ]
    assert not dirty, (
        f"{path.name}: code cells {dirty} have outputs or execution counts; "
        f"clear them before committing (jupyter nbconvert --clear-output --inplace {path.name})"
    )
    assert "widgets" not in notebook.get("metadata", {}), (
        f"{path.name}: saved widget state in the notebook metadata; remove metadata['widgets']"
    )
