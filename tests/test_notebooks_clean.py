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


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.name for p in NOTEBOOKS])
def test_every_cell_has_a_unique_id(path):
    """nbformat 4.5 requires cell ids; a missing one is a warning in CI today and an error in later nbformat."""
    cells = json.loads(path.read_text(encoding="utf-8"))["cells"]
    missing = [i for i, cell in enumerate(cells) if not cell.get("id")]
    assert not missing, (f"{path.name}: cells {missing} have no id; give each a unique \"id\" "
                         "(e.g. nbformat.validator.normalize)")
    ids = [cell["id"] for cell in cells]
    assert len(set(ids)) == len(ids), f"{path.name}: cell ids repeat: {sorted({i for i in ids if ids.count(i) > 1})}"
