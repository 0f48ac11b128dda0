"""An executed chapter shows the reader its results, never Python's plumbing: no error output, nothing written to
stderr (warnings, library logs, progress bars), no warning, traceback or kernel temporary file in any output.

The synthetic notebooks below prove each kind is caught. The chapters themselves are scanned where they execute:
.ci/test runs this file again after nbmake has written their outputs, with ``PGAE_EXECUTED_NOTEBOOKS`` set to
the folder that holds them; without it (the unit-test step, where the committed notebooks have no outputs) that
test skips.
"""
from __future__ import annotations

import json
import os
import re
from pathlib import Path

import pytest

EXECUTED = os.environ.get("PGAE_EXECUTED_NOTEBOOKS")
PLUMBING = {
    "a Python warning": re.compile(r"\b[A-Z]\w*Warning\b:"),
    "a traceback": re.compile(r"Traceback \(most recent call last\)"),
    "a kernel's temporary file": re.compile(r"/tmp/ipykernel_\d+"),
    "an installed package's path": re.compile(r"site-packages/"),
    "a tokenizer's fork notice": re.compile(r"huggingface/tokenizers"),
}


def _text(output: dict) -> str:
    if output.get("output_type") == "stream":
        text = output.get("text", "")
    else:
        text = output.get("data", {}).get("text/plain", "")
    return text if isinstance(text, str) else "".join(text)


def problems(notebook: dict) -> list[str]:
    """What in ``notebook``'s outputs is plumbing, one line each: ``cell N: what, 'the start of it'``."""
    found = []
    code = [c for c in notebook.get("cells", []) if c.get("cell_type") == "code"]
    for number, cell in enumerate(code, 1):
        for output in cell.get("outputs", []):
            text = _text(output)
            if output.get("output_type") == "error":
                found.append(f"code cell {number}: an error ({output.get('ename')}: {output.get('evalue', '')[:80]})")
                continue
            if output.get("output_type") == "stream" and output.get("name") == "stderr" and text.strip():
                found.append(f"code cell {number}: text on stderr, {text.strip()[:120]!r}")
                continue
            found += [f"code cell {number}: {what}, {text.strip()[:120]!r}"
                      for what, pattern in PLUMBING.items() if pattern.search(text)]
    return found


def _notebook(*outputs: dict) -> dict:
    return {"cells": [{"cell_type": "markdown", "source": "A Warning: in prose is the author's business"},
                      {"cell_type": "code", "source": "x", "outputs": list(outputs)}]}


def _stdout(text: str) -> dict:
    return {"output_type": "stream", "name": "stdout", "text": text}


def test_a_clean_output_passes():
    assert problems(_notebook(_stdout("describe: 100.00%\n"),
                              {"output_type": "execute_result", "data": {"text/plain": "0.25"}})) == []


@pytest.mark.parametrize("output, words", [
    ({"output_type": "error", "ename": "ValueError", "evalue": "bad", "traceback": []}, "an error (ValueError"),
    ({"output_type": "stream", "name": "stderr", "text": "100%|##########| 30/30\n"}, "text on stderr"),
    (_stdout("fill.py:14: Pandas4Warning: 'str' is not supported\n"), "a Python warning"),
    (_stdout("/tmp/ipykernel_231/27.py:14: x\n"), "a kernel's temporary file"),
    (_stdout("Traceback (most recent call last):\n  File ...\n"), "a traceback"),
    ({"output_type": "display_data", "data": {"text/plain": ["lib/python3.11/site-packages/torch/x.py: 3"]}},
     "an installed package's path"),
], ids=["error", "stderr", "warning", "temporary-file", "traceback", "package-path"])
def test_each_kind_of_plumbing_is_named(output, words):
    found = problems(_notebook(_stdout("fine\n"), output))
    assert len(found) == 1 and "code cell 1" in found[0] and words in found[0], found


@pytest.mark.skipif(not EXECUTED, reason="PGAE_EXECUTED_NOTEBOOKS is set where the chapters have executed (.ci/test)")
def test_the_executed_chapters_show_no_plumbing():
    paths = sorted(Path(EXECUTED).glob("*.ipynb"))
    assert paths, f"no notebooks in PGAE_EXECUTED_NOTEBOOKS={EXECUTED}"
    executed = [p for p in paths if any(c.get("outputs") for c in json.loads(p.read_text("utf-8"))["cells"]
                                        if c.get("cell_type") == "code")]
    assert len(executed) == len(paths), f"not executed: {sorted({p.name for p in paths} - {p.name for p in executed})}"
    found = {p.stem: problems(json.loads(p.read_text(encoding="utf-8"))) for p in paths}
    assert not any(found.values()), "plumbing in the executed chapters:\n" + "\n".join(
        f"{name}: {line}" for name, lines in found.items() for line in lines)
