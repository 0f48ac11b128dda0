"""pgae_lite.model.layers: the peephole LSTM (TensorFlow's form), the fused LSTM, the GMU."""
from __future__ import annotations

import math

import pytest
import torch

from pgae_lite.model.layers import (
    FusedLSTM,
    GatedMultimodalUnit,
    PeepholeLSTM,
    PeepholeLSTMCell,
    make_recurrent,
    state_to_vector,
    vector_to_state,
)

CLASSES = [PeepholeLSTM, FusedLSTM]


def _sig(x):
    return 1.0 / (1.0 + torch.exp(-x))


def test_peephole_cell_against_hand_computed_step():
    torch.manual_seed(1)
    inp, H, B = 3, 2, 2
    cell = PeepholeLSTMCell(inp, H).double()
    for p in cell.parameters():                                   # U(-0.1, 0.1), as in the authors' code
        assert p.abs().max() <= 0.1
    with torch.no_grad():                                         # larger values: every term matters
        for p in cell.parameters():
            p.uniform_(-1, 1)
    x = torch.randn(B, inp, dtype=torch.double)
    h = torch.randn(B, H, dtype=torch.double)
    c = torch.randn(B, H, dtype=torch.double)

    # TensorFlow's peephole LSTM, gate order i, j, f, o, forget bias 0.8, written out per gate.
    Wx, Wh, b = cell.weight_x, cell.weight_h, cell.bias
    def gate(k):
        return x @ Wx[:, k * H:(k + 1) * H] + h @ Wh[:, k * H:(k + 1) * H] + b[k * H:(k + 1) * H]
    i, j, f, o = gate(0), gate(1), gate(2), gate(3)
    c_t = _sig(f + 0.8 + cell.peep_f * c) * c + _sig(i + cell.peep_i * c) * torch.tanh(j)
    h_t = _sig(o + cell.peep_o * c_t) * torch.tanh(c_t)

    h_new, c_new = cell(x @ Wx + b, h, c)
    torch.testing.assert_close(c_new, c_t)
    torch.testing.assert_close(h_new, h_t)
    assert cell.forget_bias == 0.8


def test_peephole_cell_by_scalars():
    """One unit, every number chosen by hand."""
    cell = PeepholeLSTMCell(1, 1).double()
    with torch.no_grad():
        cell.weight_x.copy_(torch.tensor([[0.5, -0.3, 0.2, 0.1]], dtype=torch.double))   # i, j, f, o
        cell.weight_h.copy_(torch.tensor([[0.1, 0.2, -0.1, 0.3]], dtype=torch.double))
        cell.bias.copy_(torch.tensor([0.01, 0.02, 0.03, 0.04], dtype=torch.double))
        cell.peep_i.fill_(0.2), cell.peep_f.fill_(-0.4), cell.peep_o.fill_(0.6)
    x, h, c = 2.0, -0.5, 0.7
    s = lambda v: 1 / (1 + math.exp(-v))                          # noqa: E731
    i = 0.5 * x + 0.1 * h + 0.01
    j = -0.3 * x + 0.2 * h + 0.02
    f = 0.2 * x - 0.1 * h + 0.03
    o = 0.1 * x + 0.3 * h + 0.04
    c_t = s(f + 0.8 - 0.4 * c) * c + s(i + 0.2 * c) * math.tanh(j)
    h_t = s(o + 0.6 * c_t) * math.tanh(c_t)
    t = lambda v: torch.tensor([[v]], dtype=torch.double)        # noqa: E731
    with torch.no_grad():
        h_new, c_new = cell(t(x) @ cell.weight_x + cell.bias, t(h), t(c))
    assert float(c_new) == pytest.approx(c_t, rel=1e-12)
    assert float(h_new) == pytest.approx(h_t, rel=1e-12)


@pytest.mark.parametrize("cls", CLASSES)
def test_final_state_of_each_sample_is_its_own(cls):
    torch.manual_seed(0)
    rnn = cls(4, 8, num_layers=2)
    lengths = torch.tensor([7, 1, 4, 7, 2])
    x = torch.randn(5, 7, 4)
    out, (h, c) = rnn(x, lengths)
    assert out.shape == (5, 7, 8) and h.shape == c.shape == (2, 5, 8)
    for b, n in enumerate(lengths.tolist()):
        out_b, (h_b, c_b) = rnn(x[b:b + 1, :n])
        torch.testing.assert_close(h[:, b], h_b[:, 0], atol=1e-6, rtol=1e-5)
        torch.testing.assert_close(c[:, b], c_b[:, 0], atol=1e-6, rtol=1e-5)
        torch.testing.assert_close(out[b, :n], out_b[0], atol=1e-6, rtol=1e-5)


@pytest.mark.parametrize("cls", CLASSES)
def test_final_state_with_initial_state(cls):
    torch.manual_seed(0)
    rnn = cls(3, 5)
    x = torch.randn(3, 6, 3)
    lengths = torch.tensor([6, 3, 1])
    state = (torch.randn(2, 3, 5), torch.randn(2, 3, 5))
    _, (h, c) = rnn(x, lengths, state)
    for b, n in enumerate(lengths.tolist()):
        _, (h_b, c_b) = rnn(x[b:b + 1, :n], None, (state[0][:, b:b + 1], state[1][:, b:b + 1]))
        torch.testing.assert_close(h[:, b], h_b[:, 0], atol=1e-6, rtol=1e-5)
        torch.testing.assert_close(c[:, b], c_b[:, 0], atol=1e-6, rtol=1e-5)


@pytest.mark.parametrize("cls", CLASSES)
def test_gradients_reach_every_step_of_short_samples(cls):
    """The authors' code detached the frozen state of short sequences in a mixed batch."""
    torch.manual_seed(0)
    rnn = cls(4, 6)
    x = torch.randn(3, 10, 4, requires_grad=True)
    lengths = torch.tensor([10, 3, 1])
    _, (h, c) = rnn(x, lengths)
    (h.sum() + c.sum()).backward()
    g = x.grad
    for b, n in enumerate(lengths.tolist()):
        assert g[b, :n].abs().sum(-1).min() > 0, f"sample {b} (length {n}) gets no gradient at some step"
        assert (g[b, n:] == 0).all(), f"sample {b} gets gradient from padded steps"
    # Every parameter learns from the short samples alone, too.
    rnn.zero_grad()
    _, (h, c) = rnn(x.detach(), lengths)
    h[:, 1:].sum().backward()
    assert all(p.grad is not None and p.grad.abs().sum() > 0 for p in rnn.parameters())


@pytest.mark.parametrize("cls", CLASSES)
def test_step_agrees_with_forward(cls):
    torch.manual_seed(0)
    rnn = cls(4, 6)
    x = torch.randn(2, 5, 4)
    state = (torch.randn(2, 2, 6), torch.randn(2, 2, 6))
    out, (h, c) = rnn(x, None, state)
    s, outs = state, []
    for t in range(5):
        y, s = rnn.step(x[:, t], s)
        outs.append(y)
    torch.testing.assert_close(torch.stack(outs, 1), out, atol=1e-6, rtol=1e-5)
    torch.testing.assert_close(s[0], h, atol=1e-6, rtol=1e-5)
    torch.testing.assert_close(s[1], c, atol=1e-6, rtol=1e-5)


def test_fused_lstm_forget_bias_and_init():
    rnn = FusedLSTM(3, 4, num_layers=2)
    for layer in range(2):
        b = getattr(rnn.lstm, f"bias_ih_l{layer}")
        assert (b[4:8] >= 0.7).all() and (b[4:8] <= 0.9).all()       # forget gate: U(-0.1, 0.1) + 0.8
        assert b[:4].abs().max() <= 0.1 and b[8:].abs().max() <= 0.1


def test_make_recurrent():
    assert isinstance(make_recurrent("peephole", 3, 4, 2), PeepholeLSTM)
    assert isinstance(make_recurrent("lstm", 3, 4, 2), FusedLSTM)
    with pytest.raises(ValueError, match="peephole, lstm"):
        make_recurrent("gru", 3, 4, 2)


def test_state_vector_order_and_round_trip():
    layers, B, H = 2, 3, 4
    h = torch.arange(layers * B * H, dtype=torch.float).reshape(layers, B, H)
    c = -1 - h
    v = state_to_vector((h, c))
    assert v.shape == (B, 2 * layers * H)
    torch.testing.assert_close(v, torch.cat([c[0], h[0], c[1], h[1]], 1))   # [c0, h0, c1, h1]
    h2, c2 = vector_to_state(v, layers)
    assert torch.equal(h2, h) and torch.equal(c2, c)
    assert h2.is_contiguous() and c2.is_contiguous()


def test_gmu_against_its_equations():
    torch.manual_seed(0)
    gmu = GatedMultimodalUnit(action_dim=6, language_dim=4, hidden_dim=3)
    f_act, f_lang = torch.randn(5, 6), torch.randn(5, 4)
    W_A, b_A = gmu.action_linear.weight, gmu.action_linear.bias
    W_L, b_L = gmu.language_linear.weight, gmu.language_linear.bias
    W_z, b_z = gmu.gate_linear.weight, gmu.gate_linear.bias
    L_h = torch.tanh(f_lang @ W_L.T + b_L)
    A_h = torch.tanh(f_act @ W_A.T + b_A)
    z = _sig(torch.cat([f_act, f_lang], 1) @ W_z.T + b_z)                  # [f_act; f_lang]
    expected = z * A_h + (1 - z) * L_h
    h, gate = gmu(f_act, f_lang)
    torch.testing.assert_close(h, expected)
    torch.testing.assert_close(gate, z)
    assert h.shape == gate.shape == (5, 3)


def test_gmu_gate_selects_modality():
    gmu = GatedMultimodalUnit(2, 2, 2)
    with torch.no_grad():
        gmu.gate_linear.weight.zero_()
        gmu.gate_linear.bias.fill_(50.0)                                # z = 1: action only
    f_act, f_lang = torch.randn(3, 2), torch.randn(3, 2)
    h, _ = gmu(f_act, f_lang)
    torch.testing.assert_close(h, torch.tanh(gmu.action_linear(f_act)))
    with torch.no_grad():
        gmu.gate_linear.bias.fill_(-50.0)                               # z = 0: language only
    h, _ = gmu(f_act, f_lang)
    torch.testing.assert_close(h, torch.tanh(gmu.language_linear(f_lang)))


def test_gmu_normalised_action_against_its_equations():
    torch.manual_seed(0)
    gmu = GatedMultimodalUnit(action_dim=6, language_dim=4, hidden_dim=5, normalise_action=True)
    f_act, f_lang = 1000 * torch.randn(7, 6), torch.randn(7, 4)          # huge, like cell states gone wild
    a = f_act @ gmu.action_linear.weight.T + gmu.action_linear.bias
    a = (a - a.mean(1, keepdim=True)) / torch.sqrt(a.var(1, unbiased=False, keepdim=True) + 1e-5)
    z = _sig(torch.cat([f_act, f_lang], 1) @ gmu.gate_linear.weight.T + gmu.gate_linear.bias)
    L_h = torch.tanh(gmu.language_linear(f_lang))
    h, gate = gmu(f_act, f_lang)
    torch.testing.assert_close(h, z * torch.tanh(a) + (1 - z) * L_h)
    # whatever the scale of f_act, A_h keeps a spread over its dimensions: never all saturated
    A_h = torch.tanh(a)
    assert (A_h.abs() > 0.99).float().mean(1).max() < 1
    assert not GatedMultimodalUnit(6, 4, 5).normalise_action             # the paper's GMU by default
