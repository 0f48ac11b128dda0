"""What every lab (pgae_lite.course.labs) must do, one test per promise over all of LABS: its check passes the
reference on two seeds and fails the book's own component, names each deliberate mistake, leaves the global random
state alone, and its committed runs are the lab's, with a three-seed reference table, within a class period.
What only one lab does is tested in its own file (tests/test_lab_NAME.py)."""
from __future__ import annotations

import pytest
import torch

from pgae_lite.course.labs import LABS, lab
from pgae_lite.course.labs.compare import reference_table
from pgae_lite.runs.results import load

CLASS_PERIOD = 600          # seconds: the longest run of a lab on the 2-core CPU (issue 61)
MISTAKES = [(name, mistake) for name in LABS for mistake in lab(name).WRONG]


def words_of(words) -> list[str]:
    return [words] if isinstance(words, str) else list(words)


@pytest.mark.parametrize("seed", [0, 3])
@pytest.mark.parametrize("name", LABS)
def test_the_reference_passes_and_the_books_component_does_not(name, seed):
    result = lab(name).check(lab(name).REFERENCE, seed=seed)
    assert result, str(result)
    assert not lab(name).check(lab(name).BASELINE)


@pytest.mark.parametrize("name, mistake", MISTAKES, ids=[f"{n}-{m}" for n, m in MISTAKES])
def test_each_mistake_gets_its_diagnosis(name, mistake):
    component, words = lab(name).WRONG[mistake]
    result = lab(name).check(component)
    assert not result and all(w in str(result) for w in words_of(words)), str(result)


@pytest.mark.parametrize("name", LABS)
def test_the_check_leaves_the_global_random_state_alone(name):
    torch.manual_seed(5)
    before = torch.get_rng_state()
    lab(name).check(lab(name).REFERENCE)
    assert torch.equal(before, torch.get_rng_state())


@pytest.mark.parametrize("name", LABS)
def test_the_committed_runs_are_the_labs_and_fit_a_class_period(name):
    result = load(f"lab-{name}")
    data = result["data"]
    assert data["figures"] == lab(name).FIGURES and data["title"] == lab(name).TITLE
    table = reference_table(name)
    assert len(table) == 6 and set(table.columns) >= set(lab(name).FIGURES)     # 2 variants x 3 seeds
    assert result["profile"] == "book" and data["longest_seconds"] <= CLASS_PERIOD
