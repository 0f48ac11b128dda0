"""No formula of a chapter breaks into a list: a source line inside inline math never starts like a list item.

Markdown reads a line that starts with ``+ ``, ``- ``, ``* `` or ``1. `` as a list item before it reads
math, so ``$\\gamma (h - \\mu) / \\sqrt{\\sigma^2 + \\epsilon}`` on one line and ``+ \\beta$`` on the next
renders as raw TeX and a stray bullet. Lines inside code fences are not math.
"""
import json
import re
from pathlib import Path

import pytest

NOTEBOOKS = sorted((Path(__file__).resolve().parent.parent / "notebooks").glob("*.ipynb"))
LIST_ITEM = re.compile(r"\s*(?:[-+*]|\d+[.)])\s")


def broken_formulas(markdown: str) -> list[str]:
    """The lines of ``markdown`` that start like a list item while an inline ``$...$`` is open."""
    broken, open_math, fenced = [], False, False
    for line in markdown.split("\n"):
        if line.lstrip().startswith("```"):
            fenced = not fenced
            continue
        if fenced:
            continue
        if open_math and LIST_ITEM.match(line):
            broken.append(line)
        open_math ^= line.replace(r"\$", "").count("$") % 2 == 1
    return broken


def test_the_check_finds_a_broken_formula():
    assert broken_formulas("scales it: $\\gamma h / \\sigma\n+ \\beta$.") == ["+ \\beta$."]
    assert broken_formulas("$a + b$\n- a list item\n$$x\n+ y$$") == []


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.name for p in NOTEBOOKS])
def test_no_formula_breaks_into_a_list(path):
    cells = json.loads(path.read_text(encoding="utf-8"))["cells"]
    broken = [(cell.get("id"), line) for cell in cells if cell["cell_type"] == "markdown"
              for line in broken_formulas("".join(cell["source"]))]
    assert not broken, f"{path.name}: a formula's line starts like a list item (join it to the line before): {broken}"
