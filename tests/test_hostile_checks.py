"""The exercise checks against hostile and careless student code (issue 21).

Stubs that return None, steps that change the reference's weights, NaN and inf,
wrong dtypes, student code that raises, and colours or probabilities that are
not finite numbers: each check fails with a sentence saying what it got, and
never raises.
"""
from __future__ import annotations

import math

import pytest
import torch
from hypothesis import given, settings
from hypothesis import strategies as st

from pgae_lite.exercises import (
    CheckResult,
    check_bottleneck,
    check_colour,
    check_gmu,
    check_lstm_step,
    check_peephole_step,
    check_signal_probs,
)
from pgae_lite.model.layers import GatedMultimodalUnit

ORANGE = (0.98, 0.5, 0.05, 1.0)


def package_step(x, state, cell):
    """A right answer: the package's peephole cell, one step."""
    return cell(x @ cell.weight_x + cell.bias, *state)


def gmu_forward(gmu, f_action, f_language):
    """A right answer: the package's GMU forward."""
    return gmu(f_action, f_language)


def failed_with(result: CheckResult, *phrases: str) -> bool:
    """The check failed, and its report contains every phrase."""
    text = str(result)
    return not result and all(p in text for p in phrases)


def step_stub(x, state, cell):
    """An unfinished exercise: the body is still to be written."""


STEP_CHECKS = [check_peephole_step, check_lstm_step]


# ------------------------------------------------------------------ stubs returning None
@pytest.mark.parametrize("check", STEP_CHECKS)
def test_step_stub_returning_none_fails(check):
    result = check(step_stub)
    assert failed_with(result, "your step returned None; expected the pair (h, c), "
                               "two tensors of shape (5, 4)"), result


def test_gmu_stub_returning_none_fails():
    class Stub(GatedMultimodalUnit):
        def forward(self, f_action, f_language):
            pass
    for student in (lambda gmu, f_action, f_language: None, Stub):
        result = check_gmu(student)
        assert failed_with(result, "your GMU returned None; expected the pair (h, z), "
                                   "two tensors of shape (6, 4)"), result


class StubBottleneck(GatedMultimodalUnit):
    def forward(self, f_action, f_language):
        pass


@pytest.mark.parametrize("factory, phrases", [
    (StubBottleneck, ["your module returned None; expected the pair (h, z)", "(4, 6)"]),
    (lambda action, language, hidden: None, ["factory(12, 9, 6) returned None", "nn.Module"]),
])
def test_bottleneck_stub_returning_none_fails(factory, phrases):
    result = check_bottleneck(factory)
    assert failed_with(result, *phrases), result


# ------------------------------------------------------------------ mutating the reference
def zeroing_step(x, state, cell):
    """Zeroes the cell's weights, then returns what the zeroed cell computes."""
    with torch.no_grad():
        for p in cell.parameters():
            p.zero_()
    return package_step(x, state, cell)


def test_step_that_changes_the_cells_weights_fails():
    result = check_peephole_step(zeroing_step)
    assert failed_with(result, "your step changed cell.weight_x, cell.weight_h, cell.bias",
                       "in place", "h_t differs"), result


def test_gmu_that_changes_the_weights_or_inputs_fails():
    def zeroing(gmu, f_action, f_language):
        with torch.no_grad():
            gmu.gate_linear.weight.zero_()
        return gmu_forward(gmu, f_action, f_language)

    def scaling(gmu, f_action, f_language):
        f_action.mul_(2)
        return gmu_forward(gmu, f_action, f_language)
    assert failed_with(check_gmu(zeroing), "changed gate_linear.weight in place", "z differs")
    assert failed_with(check_gmu(scaling), "changed f_action in place", "h differs")


# ------------------------------------------------------------------ NaN, inf and dtypes
@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf])
def test_step_with_non_finite_output_fails(value):
    def step(x, state, cell):
        h, c = package_step(x, state, cell)
        return h, c.index_fill(1, torch.tensor([2]), value)
    result = check_peephole_step(step)
    assert failed_with(result, "c_t has 5 NaN or infinite entries of 20",
                       f"the first is at index (0, 2): {value}"), result


def test_gmu_with_wrong_dtype_fails():
    def doubled(gmu, f_action, f_language):
        return tuple(t.double() for t in gmu_forward(gmu, f_action, f_language))
    result = check_gmu(doubled)
    assert failed_with(result, "h is a torch.float64 tensor on cpu; expected torch.float32"), result


class NaNGate(GatedMultimodalUnit):
    def forward(self, f_action, f_language):
        h, z = super().forward(f_action, f_language)
        return h, z * math.nan


def test_bottleneck_with_non_finite_gate_fails():
    """z is not in the loss, so only the check of the outputs alone can see this."""
    result = check_bottleneck(NaNGate)
    assert failed_with(result, "z has 24 NaN or infinite entries of 24"), result


# ------------------------------------------------------------------ student code that raises
def raising(*args):
    raise KeyError("h_prev")


@pytest.mark.parametrize("check", [check_peephole_step, check_lstm_step, check_gmu])
def test_raising_student_code_is_a_failure_not_a_traceback(check):
    result = check(raising)
    assert failed_with(result, "raised KeyError: 'h_prev'"), result


def test_raising_bottleneck_forward_and_factory_fail():
    class Raising(GatedMultimodalUnit):
        forward = raising
    assert failed_with(check_bottleneck(Raising), "your module on f_action (4, 12)",
                       "raised KeyError")
    assert failed_with(check_bottleneck(raising), "factory(12, 9, 6) raised KeyError")


# ------------------------------------------------------------------ colours and probabilities
@pytest.mark.parametrize("rgba, phrases", [
    ([math.nan, math.nan, math.nan, 1], ["must be finite numbers; got [nan, nan, nan, 1]"]),
    ((0.98, math.inf, 0.05, 1.0), ["must be finite numbers"]),
    (("0.98", 0.5, 0.05, 1.0), ["must be finite numbers; got ('0.98'"]),
    (None, ["must be finite numbers; got None"]),
    ("pink", ["must be finite numbers; got 'pink'"]),
    ((0.98, 0.5, 1j, 1.0), ["must be finite numbers"]),
    ((), ["an RGBA colour has 4 numbers; got 0"]),
    ((0.98, 0.5, 0.05, 1.0, 1.0), ["an RGBA colour has 4 numbers; got 5"]),
    ((0.98, -0.5, 0.05, 1.0), ["must lie in [0, 1]"]),
])
def test_colour_rejects_what_is_not_four_finite_numbers(rgba, phrases):
    result = check_colour("pink", rgba)
    assert failed_with(result, *phrases), result


def test_colour_accepts_a_tensor():
    assert check_colour("orange", torch.tensor(ORANGE))


@settings(max_examples=60, deadline=None)
@given(bad=st.one_of(st.sampled_from([math.nan, math.inf, -math.inf]),
                     st.floats(max_value=-1e-9), st.floats(min_value=1 + 1e-9)),
       at=st.integers(0, 3))
def test_colour_with_any_non_finite_or_out_of_range_value_fails(bad, at):
    rgba = list(ORANGE)
    rgba[at] = bad
    result = check_colour("orange", rgba)
    assert not result and ("finite numbers" in str(result) or "[0, 1]" in str(result))


@pytest.mark.parametrize("probs, drop, phrases", [
    (None, "repeat both", ["must be finite numbers; got None", "give 5 numbers"]),
    ((math.nan, 0.5, 0.25, 0, 0.25), "repeat both", ["must be finite numbers"]),
    ({"describe": "half", "execute": 0.5}, "repeat both", ["must be finite numbers"]),
    ({1: 0.5, "repeat lang": 0.5}, "repeat both", ["unknown signal name(s) ['repeat lang', 1]"]),
    ((0.25, 0.25, 0.25, 0, 0.25), "repeat everything",
     ["drop is 'repeat everything'; expected None or one of the signals"]),
])
def test_signal_probs_reject_what_is_not_finite_numbers(probs, drop, phrases):
    result = check_signal_probs(probs, drop=drop)
    assert failed_with(result, *phrases), result


def test_the_reference_solutions_still_pass():
    """The new checks reject nothing the book's reference solutions do."""
    assert check_peephole_step(package_step) and check_gmu(gmu_forward)
    assert check_gmu(GatedMultimodalUnit) and check_bottleneck(GatedMultimodalUnit)


@pytest.mark.parametrize("words", [None, "red", [3, "red"], [["red"]], {"red": 1}])
def test_check_vocabulary_refuses_what_is_not_a_list_of_words(words):
    from pgae_lite.exercises import check_vocabulary

    result = check_vocabulary(words)
    assert not result and "list of strings" in str(result)
