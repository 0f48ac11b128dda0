"""Each notebook's settings cell: it takes its profile from pgae_lite.config and refuses an unknown one clearly.

Only the settings cell runs here (imports and a few names, no data); CI runs the
whole notebooks (nbmake, smoke profile).
"""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from pgae_lite.config import PROFILE_ENV, get_profile

# Every chapter but the results page, the teachers' page and the contributors' notes, which only read result files
# (no profile, no seed).
NOTEBOOKS = sorted(p for p in (Path(__file__).resolve().parent.parent / "notebooks").glob("*.ipynb")
                   if p.stem not in ("A2_results", "A5_teaching", "A6_engineering"))


def settings_cell(path: Path) -> str:
    """The source of the notebook's settings cell: the first code cell that sets SEED."""
    cells = json.loads(path.read_text(encoding="utf-8"))["cells"]
    return next("".join(c["source"]) for c in cells if c["cell_type"] == "code" and "SEED = " in "".join(c["source"]))


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.name for p in NOTEBOOKS])
def test_settings_cell_refuses_an_unknown_profile(path, monkeypatch):
    monkeypatch.setenv(PROFILE_ENV, "garbage")
    with pytest.raises(ValueError) as e:
        exec(settings_cell(path), {})
    assert str(e.value) == (f"unknown profile 'garbage' (from the environment variable {PROFILE_ENV}); "
                            "the profiles are: smoke, book, paper")


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.name for p in NOTEBOOKS])
def test_settings_cell_reads_the_profile(path, monkeypatch, capsys):
    monkeypatch.setenv(PROFILE_ENV, "smoke")
    monkeypatch.delenv("PGAE_ORIGINAL_DATA", raising=False)
    names = {}
    exec(settings_cell(path), names)
    profile = names["PROFILE"] if isinstance(names["PROFILE"], str) else names["PROFILE"].name
    assert profile == "smoke"
    chapters = get_profile("smoke").chapters
    expected = {"RUNS": chapters.runs_per_action, "EPISODES": chapters.test_episodes,
                "PARAPHRASES": chapters.paraphrase_episodes, "EVERY": chapters.every,
                "DATA": get_profile("smoke").data, "CAE": get_profile("smoke").cae}
    for name, value in expected.items():
        if name in names and not (name == "DATA" and path.name.startswith("A1")):   # A1's DATA: a folder
            assert names[name] == value, name
    if path.name.startswith("04"):
        assert names["PROFILE"].train == get_profile("smoke").train     # the recipe, as every chapter
