"""pgae_lite.exercises: every check passes the reference solution and names typical mistakes.

The reference solutions here are the ones the book's exercises show in their folded solutions.
"""
from __future__ import annotations

import pytest
import torch
from torch import nn

from pgae_lite.config import get_profile
from pgae_lite.exercises import (
    CheckResult,
    check_bottleneck,
    check_colour,
    check_gmu,
    check_lstm_step,
    check_peephole_step,
    check_signal_probs,
    check_vocabulary,
)
from pgae_lite.model.layers import (
    ConcatBottleneck,  # the reference answer of the concatenation exercise
    GatedMultimodalUnit,
)
from pgae_lite.train.loop import train
from pgae_lite.world.words import VOCABULARY


def failed_with(result: CheckResult, *phrases: str) -> bool:
    """The check failed, and its report contains every phrase."""
    text = str(result)
    return not result and all(p in text for p in phrases)


def test_result_is_truthy_printable_and_assertable():
    good, bad = CheckResult("a"), CheckResult("b").fail("wrong", "do this")
    assert good and not bad
    assert str(good).startswith("a: passed")
    assert "✗ wrong" in str(bad) and "hint: do this" in repr(bad)
    with pytest.raises(AssertionError):
        assert bad, bad


# ------------------------------------------------------------------ (a), (d) LSTM steps
def peephole_step(x, state, cell):
    """The reference solution: TensorFlow's peephole LSTM, gates i, j, f, o, forget bias 0.8."""
    h, c = state
    i, j, f, o = (x @ cell.weight_x + h @ cell.weight_h + cell.bias).chunk(4, dim=1)
    c_new = torch.sigmoid(f + 0.8 + cell.peep_f * c) * c + torch.sigmoid(i + cell.peep_i * c) * torch.tanh(j)
    h_new = torch.sigmoid(o + cell.peep_o * c_new) * torch.tanh(c_new)
    return h_new, c_new


def lstm_step(x, state, cell):
    """The reference solution without peepholes."""
    h, c = state
    i, j, f, o = (x @ cell.weight_x + h @ cell.weight_h + cell.bias).chunk(4, dim=1)
    c_new = torch.sigmoid(f + 0.8) * c + torch.sigmoid(i) * torch.tanh(j)
    return torch.sigmoid(o) * torch.tanh(c_new), c_new


def mistaken_step(order="ijfo", forget_bias=0.8, peepholes=True, tanh_j=True, tanh_c=True, o_new_c=True):
    def step(x, state, cell):
        h, c = state
        g = dict(zip(order, (x @ cell.weight_x + h @ cell.weight_h + cell.bias).chunk(4, dim=1)))
        p_i, p_f, p_o = (cell.peep_i, cell.peep_f, cell.peep_o) if peepholes else (0, 0, 0)
        c_new = (torch.sigmoid(g["f"] + forget_bias + p_f * c) * c
                 + torch.sigmoid(g["i"] + p_i * c) * (torch.tanh(g["j"]) if tanh_j else g["j"]))
        out = torch.sigmoid(g["o"] + p_o * (c_new if o_new_c else c))
        return out * (torch.tanh(c_new) if tanh_c else c_new), c_new
    return step


def test_peephole_step_passes_the_reference_and_the_package_cell():
    assert check_peephole_step(peephole_step)
    assert check_peephole_step(lambda x, state, cell: cell(x @ cell.weight_x + cell.bias, *state))
    assert check_peephole_step(mistaken_step(), seed=3)


def in_place(x, state, cell):
    h, c = peephole_step(x, state, cell)
    state[1].mul_(2)
    return h, c


@pytest.mark.parametrize("student, phrases", [
    (mistaken_step(order="ifjo"), ["order i, f, j, o", "PyTorch", "i, j, f, o"]),
    (mistaken_step(order="jifo"), ["order j, i, f, o"]),
    (mistaken_step(forget_bias=0.0), ["forget bias 0.8 is missing"]),
    (mistaken_step(forget_bias=1.0), ["not 1.0"]),
    (mistaken_step(peepholes=False), ["left out the peepholes"]),
    (mistaken_step(tanh_j=False), ["tanh(j)"]),
    (mistaken_step(tanh_c=False), ["tanh of the cell state"]),
    (mistaken_step(o_new_c=False), ["NEW cell state"]),
    (lambda x, s, cell: peephole_step(x, s, cell)[::-1], ["return (c, h)"]),
    (lambda x, s, cell: (peephole_step(x, s, cell)[0][:, :2], peephole_step(x, s, cell)[1]),
     ["h_t has shape (5, 2); expected a tensor of shape (5, 4)"]),
    (lambda x, s, cell: peephole_step(x, s, cell)[0], ["pair (h, c)"]),
    (lambda x, s, cell: 1 / 0, ["raised ZeroDivisionError"]),
    (in_place, ["in place"]),
    (lambda x, s, cell: (s[0] * 0.5, s[1] * 0.5), ["differs at", "largest difference", "compare each term"]),
])
def test_peephole_step_names_the_mistake(student, phrases):
    assert failed_with(check_peephole_step(student), *phrases)


def test_lstm_step_without_peepholes():
    result = check_lstm_step(lstm_step)
    assert result and "nn.LSTMCell" in str(result)
    assert failed_with(check_lstm_step(peephole_step), "still use the peepholes")
    assert failed_with(check_lstm_step(mistaken_step(peepholes=False, forget_bias=0.0)), "forget bias 0.8 is missing")
    assert failed_with(check_lstm_step(mistaken_step(peepholes=False, order="ifjo")), "PyTorch")


def test_lstm_step_is_torch_lstm_cell_with_copied_weights():
    """(d) the other way round: nn.LSTMCell, given the cell's weights reordered, passes the check."""
    def via_lstm_cell(x, state, cell):
        def reorder(w):                                             # i, j, f, o -> PyTorch's i, f, j, o
            i, j, f, o = w.chunk(4, dim=0)
            return torch.cat([i, f, j, o])
        H = cell.hidden_size
        lstm = nn.LSTMCell(x.shape[1], H)
        with torch.no_grad():
            lstm.weight_ih.copy_(reorder(cell.weight_x.T))
            lstm.weight_hh.copy_(reorder(cell.weight_h.T))
            lstm.bias_ih.copy_(reorder(cell.bias + torch.cat([torch.zeros(2 * H), torch.full((H,), 0.8),
                                                             torch.zeros(H)])))
            lstm.bias_hh.zero_()
        return lstm(x, state)
    assert check_lstm_step(via_lstm_cell)


# ------------------------------------------------------------------ (b) the GMU
class MyGMU(nn.Module):
    """The reference solution as a module."""

    def __init__(self, action_dim, language_dim, hidden_dim=50):
        super().__init__()
        self.action_linear = nn.Linear(action_dim, hidden_dim)
        self.language_linear = nn.Linear(language_dim, hidden_dim)
        self.gate_linear = nn.Linear(action_dim + language_dim, hidden_dim)

    def forward(self, f_action, f_language):
        a_h = torch.tanh(self.action_linear(f_action))
        l_h = torch.tanh(self.language_linear(f_language))
        z = torch.sigmoid(self.gate_linear(torch.cat([f_action, f_language], dim=1)))
        return z * a_h + (1 - z) * l_h, z


def gmu_forward(gmu, f_action, f_language):
    """The reference solution as a function of the package's GMU (chapter 4's five lines)."""
    return MyGMU.forward(gmu, f_action, f_language)


def test_gmu_passes_module_class_instance_and_function():
    assert check_gmu(MyGMU)
    assert check_gmu(MyGMU(400, 400, 50))
    assert check_gmu(GatedMultimodalUnit)
    assert check_gmu(gmu_forward)


def gmu_variant(h_of, z_of=torch.sigmoid, gate_input=lambda a, lang: torch.cat([a, lang], 1), squash=torch.tanh):
    def forward(gmu, a, lang):
        a_h, l_h = squash(gmu.action_linear(a)), squash(gmu.language_linear(lang))
        z = z_of(gmu.gate_linear(gate_input(a, lang)))
        return h_of(z, a_h, l_h), z
    return forward


REFERENCE_H = lambda z, a, lang: z * a + (1 - z) * lang  # noqa: E731


@pytest.mark.parametrize("student, phrases", [
    (gmu_variant(lambda z, a, lang: z * lang + (1 - z) * a),
     ["z should weight the ACTION features: h = z*A_h + (1-z)*L_h"]),
    (gmu_variant(REFERENCE_H, gate_input=lambda a, lang: torch.cat([lang, a], 1)), ["action features first"]),
    (gmu_variant(REFERENCE_H, squash=lambda t: t), ["need a tanh"]),
    (gmu_variant(REFERENCE_H, z_of=lambda t: t), ["z needs a sigmoid"]),
    (gmu_variant(lambda z, a, lang: z * a + lang), ["(1 - z)"]),
    (lambda gmu, a, lang: gmu_forward(gmu, a, lang)[::-1], ["return (z, h)"]),
    (lambda gmu, a, lang: gmu_forward(gmu, a, lang)[0], ["pair (h, z)"]),
    (lambda gmu, a, lang: (gmu_forward(gmu, a, lang)[0][:, :1], gmu_forward(gmu, a, lang)[1]), ["h has shape (6, 1)"]),
])
def test_gmu_names_the_mistake(student, phrases):
    result = check_gmu(student)
    assert failed_with(result, *phrases), result


def test_gmu_module_with_other_layer_names_is_told_the_names():
    class Renamed(nn.Module):
        def __init__(self, a, lang, h):
            super().__init__()
            self.wa, self.wl, self.wz = nn.Linear(a, h), nn.Linear(lang, h), nn.Linear(a + lang, h)
    assert failed_with(check_gmu(Renamed), "cannot copy the reference weights", "action_linear.weight")
    assert failed_with(check_gmu(type("NoArgs", (nn.Module,), {})), "NoArgs(7, 5, 4) raised TypeError")


# ------------------------------------------------------------------ (c) a bottleneck in PGAE
@pytest.mark.parametrize("cell", ["lstm", "peephole"])
def test_bottleneck_passes_concatenation_and_the_gmu(cell):
    result = check_bottleneck(ConcatBottleneck, cell=cell)
    assert result and "backward pass done" in str(result)
    assert "yours 40,050, the GMU's 80,150" in str(result)
    assert check_bottleneck(GatedMultimodalUnit, cell=cell)
    assert check_bottleneck(lambda a, lang, h: ConcatBottleneck(a, lang, h))


class TwiceTheAction(ConcatBottleneck):
    def __init__(self, action_dim, language_dim, hidden_dim=50):
        super().__init__(action_dim, action_dim, hidden_dim)


class OnlyH(ConcatBottleneck):
    def forward(self, f_action, f_language):
        return super().forward(f_action, f_language)[0]


class FlatGate(ConcatBottleneck):
    def forward(self, f_action, f_language):
        h, _ = super().forward(f_action, f_language)
        return h, torch.full((len(h),), 0.5)


class Detached(ConcatBottleneck):
    def forward(self, f_action, f_language):
        return super().forward(f_action.detach(), f_language)


class Unused(ConcatBottleneck):
    def __init__(self, action_dim, language_dim, hidden_dim=50):
        super().__init__(action_dim, language_dim, hidden_dim)
        self.gate = nn.Linear(action_dim + language_dim, hidden_dim)


class NotANumber(ConcatBottleneck):
    def forward(self, f_action, f_language):
        h, z = super().forward(f_action, f_language)
        return h * float("nan"), z


@pytest.mark.parametrize("factory, phrases", [
    (TwiceTheAction, ["raised RuntimeError", "language_dim numbers"]),
    (OnlyH, ["pair (h, z)", "constant one"]),
    (FlatGate, ["z has shape (4,); expected (batch, hidden) = (4, 6)"]),
    (Detached, ["no gradient reaches the action_encoder", ".detach()"]),
    (Unused, ["no gradient reaches your parameter(s) ['gate.weight', 'gate.bias']"]),
    (NotANumber, ["the loss is nan"]),
    (lambda a, lang, h: nn.Linear(a + lang, h), ["raised TypeError", "takes both"]),
    (lambda a, lang, h: "concat", ["returned a str", "nn.Module"]),
])
def test_bottleneck_names_the_mistake(factory, phrases):
    result = check_bottleneck(factory)
    assert failed_with(result, *phrases), result


# ------------------------------------------------------------------ (e) signal probabilities
NO_REPEAT_BOTH = (3 / 8, 3 / 8, 1 / 8, 0.0, 1 / 8)   # the reference solution: the authors' ratios, renormalised


def test_signal_probs_pass():
    result = check_signal_probs(NO_REPEAT_BOTH)
    assert result and "authors' ratios" in str(result) and "repeat both 0.000" in str(result)
    assert check_signal_probs({"describe": 0.25, "execute": 0.25, "repeat action": 0.25, "repeat language": 0.25})
    assert check_signal_probs((3 / 9, 3 / 9, 1 / 9, 1 / 9, 1 / 9), drop=None)


@pytest.mark.parametrize("probs, phrases", [
    ((3 / 9, 3 / 9, 1 / 9, 0, 1 / 9), ["sum to 0.8889, not 1", "divide each by their sum"]),
    ((0.3, 0.3, 0.1, 0.2, 0.1), ["'repeat both' still has probability 0.2000"]),
    ((0.5, 0.5, 0, 0, 0), ["'repeat action' has probability 0", "Table 1"]),
    ((0.25, 0.25, 0.25, 0.25), ["4 probabilities; expected 5"]),
    ((0.6, 0.6, -0.2, 0, 0), ["negative"]),
    ({"describe": 0.5, "execute": 0.5, "repeat lang": 0.0}, ["unknown signal name(s) ['repeat lang']"]),
])
def test_signal_probs_name_the_mistake(probs, phrases):
    assert failed_with(check_signal_probs(probs), *phrases)


def test_training_without_repeat_both(toy_short):
    """The exercise's recipe: the checked probabilities as the profile's signal_probs; "repeat both" is never drawn."""
    assert "get_profile(..., signal_probs=probs)" in str(check_signal_probs(NO_REPEAT_BOTH))
    short = dict(epochs=3, batch_size=4, max_train_samples=12)
    tiny = get_profile("smoke", signal_probs=NO_REPEAT_BOTH, **short)
    assert tiny.to_dict() != get_profile("smoke", **short).to_dict()     # its own checkpoints and cache entries
    trained = train(toy_short, tiny, progress=False, device="cpu")
    drawn = set().union(*(record["gate"] for record in trained.history))
    assert "repeat both" not in drawn and {"describe", "execute"} <= drawn


# ------------------------------------------------------------------ (f) vocabulary and colours
def test_vocabulary():
    result = check_vocabulary(list(VOCABULARY) + ["orange", "amber"], new=("orange", "amber"))
    assert result and "25 output words, 30 input dimensions" in str(result)
    assert failed_with(check_vocabulary(sorted(VOCABULARY[1:] + ("orange",))), "position 0 holds 'azure'")
    assert failed_with(check_vocabulary(["<BOS/EOS>", "orange", *VOCABULARY[1:]]), "position 1 holds 'orange'",
                       "append")
    assert failed_with(check_vocabulary(list(VOCABULARY) + ["red"]), "duplicate word(s) ['red']")
    assert failed_with(check_vocabulary(list(VOCABULARY) + ["dark orange"]), "hyphen")
    assert failed_with(check_vocabulary(list(VOCABULARY) + ["Orange"], new=["orange"]), "['orange'] not among")
    assert failed_with(check_vocabulary(VOCABULARY[:-1]), "position 22 holds 'nothing'")


def test_colour():
    result = check_colour("orange", (0.98, 0.50, 0.05, 1.0))
    assert result and "nearest is the yellow cube" in str(result)
    from pgae_lite.sim import scene as S
    S.CUBE_RGBA["orange"] = (0.98, 0.50, 0.05, 1.0)      # checking after adding it also works
    try:
        assert check_colour("orange", S.CUBE_RGBA["orange"])
    finally:
        del S.CUBE_RGBA["orange"]
    assert failed_with(check_colour("crimson", (0.8, 0.1, 0.1, 1.0)), "too close to the red cube")
    assert failed_with(check_colour("sand", (0.8, 0.75, 0.62, 1.0)), "too close to the table")
    assert failed_with(check_colour("orange", (250, 128, 13)), "divide 0..255 values by 255", "add the alpha")
    assert failed_with(check_colour("orange", (0.98, 0.5, 0.05, 0.5)), "opaque")
    assert failed_with(check_colour("red", (0.98, 0.5, 0.05, 1.0)), "already one of the six colours")
    assert failed_with(check_colour("dark orange", (0.98, 0.5, 0.05, 1.0)), "one lowercase word")


def test_checks_leave_the_global_random_state_alone_and_repeat_exactly():
    torch.manual_seed(5)
    expected = torch.rand(3)
    torch.manual_seed(5)
    first = str(check_bottleneck(ConcatBottleneck))
    check_gmu(MyGMU), check_peephole_step(peephole_step)
    assert torch.equal(torch.rand(3), expected)
    assert str(check_bottleneck(ConcatBottleneck)) == first


# ------------------------------------------------------------------ chapter 09: the binding loss
def test_check_binding_loss_passes_the_equation_and_names_each_known_mistake():
    from pgae_lite.exercises import check_binding_loss
    from pgae_lite.exercises.family import MISTAKES, _variant

    def mine(z_language, z_action, margin):
        d = torch.cdist(z_action, z_language)
        b, own = len(d), d.diagonal()
        push = [max(0.0, margin + own[j] - d[i, j]) + max(0.0, margin + own[i] - d[i, j])
                for i in range(b) for j in range(b) if i != j]
        return own.mean() + sum(push) / b ** 2

    assert check_binding_loss(mine)
    for mistake, switches in MISTAKES.items():
        result = check_binding_loss(lambda zl, za, m, s=switches: _variant(zl, za, m, **s))
        assert not result and mistake in str(result)
    broken = check_binding_loss(lambda zl, za, m: 1 / 0)
    assert not broken and "ZeroDivisionError" in str(broken)
