"""The concatenation lab (pgae_lite.course.labs.concat): its check passes the reference, diagnoses the book's GMU
and each deliberate mistake, never raises on a student's code, and its run returns the lab's figures."""
from __future__ import annotations

import math

import pytest
from torch import nn

from pgae_lite.course.labs import lab
from pgae_lite.runs.results import load
from pgae_lite.util.errors import ArgumentError, ArgumentTypeError

concat = lab("concat")


def failed_with(result, words) -> bool:
    text = str(result)
    return not result and all(w in text for w in words)


def test_the_reference_is_told_its_size_beside_the_gmus():
    assert "40,050" in str(concat.check(concat.REFERENCE))     # at the book's sizes, beside the GMU's 80,150


def test_the_book_gmu_is_told_it_gates():
    result = concat.check(concat.BASELINE)
    assert failed_with(result, ["gate parameters", "the GMU's (W_A, W_L and the gate W_z)",
                                "z changes with the inputs"]), str(result)


def test_students_unfinished_code_fails_without_raising():
    class Stub(nn.Module):                                  # the handed-out notebook's cell, untouched
        def __init__(self, action_dim, language_dim, hidden_dim=50):
            super().__init__()

        def forward(self, f_action, f_language):
            ...

    class NoInit(nn.Module):                                # super().__init__() forgotten
        def __init__(self, action_dim, language_dim, hidden_dim=50):
            pass

    assert failed_with(concat.check(Stub), ["0 parameters", "must return (h, z)"])
    assert failed_with(concat.check(NoInit), ["super().__init__()"])
    assert failed_with(concat.check(lambda a, b, c: 3), ["returned a int"])


def test_bad_arguments_are_clear_errors():
    with pytest.raises(ArgumentTypeError, match="seed"):
        concat.check(concat.REFERENCE, seed=1.5)
    with pytest.raises(ArgumentTypeError, match="builds the bottleneck"):
        concat.run("ConcatBottleneck", profile="smoke")
    for returned in (None, 3):
        with pytest.raises(ArgumentTypeError, match="not an nn.Module"):
            concat.run(lambda a, b, c, returned=returned: returned, profile="smoke")
    with pytest.raises(ArgumentError, match="profile"):
        concat.run(concat.REFERENCE, profile="tiny")


def test_the_run_returns_the_figures_and_repeats_itself():
    figures = concat.run(concat.REFERENCE, seed=0, profile="smoke")    # the smoke profile: its own 3 epochs
    assert set(figures) == set(concat.FIGURES)
    assert all(math.isfinite(v) for v in figures.values())
    assert figures == concat.run(concat.REFERENCE, seed=0, profile="smoke")


def test_the_committed_runs_show_the_effect():
    """At the lab's budget the concatenation's describe accuracy lies below every seed of the GMU's."""
    runs = load("lab-concat")["data"]["runs"]
    describe = {v: [r["figures"]["describe"] for r in runs if r["variant"] == v] for v in ("baseline", "reference")}
    assert max(describe["reference"]) < min(describe["baseline"]), describe
