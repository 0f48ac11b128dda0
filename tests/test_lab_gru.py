"""The GRU lab (pgae_lite.course.labs.gru) and the hook it trains through (pgae_lite.model.layers.recurrent_layers):
the check passes the reference GRU, diagnoses the book's LSTM and each deliberate mistake, its run returns the lab's
figures, and a model built outside the hook is the one built without it."""
from __future__ import annotations

import math

import pytest
import torch
from torch import nn

from pgae_lite.course.labs import lab
from pgae_lite.model.config import ModelConfig
from pgae_lite.model.layers import FusedLSTM, PeepholeLSTM, recurrent_layers
from pgae_lite.model.pgae import PGAE
from pgae_lite.util.errors import ArgumentTypeError

gru = lab("gru")
PARTS = ("language_encoder", "action_encoder", "language_decoder", "action_decoder")


def failed_with(result, words) -> bool:
    text = str(result)
    return not result and all(w in text for w in words)


def test_the_reference_steps_as_torch_gru():
    """The lab's equations are torch.nn.GRU's: with its weights, the reference gives its outputs."""
    torch.manual_seed(0)
    ours, theirs = gru.GRU(3, 4, 2), nn.GRU(3, 4, 2, batch_first=True)
    with torch.no_grad():
        for layer, cell in enumerate(ours.cells):
            cell.weight_x.copy_(getattr(theirs, f"weight_ih_l{layer}").T)
            cell.weight_h.copy_(getattr(theirs, f"weight_hh_l{layer}").T)
            cell.bias_x.copy_(getattr(theirs, f"bias_ih_l{layer}"))
            cell.bias_h.copy_(getattr(theirs, f"bias_hh_l{layer}"))
        x = torch.randn(5, 6, 3)
        y, (h, c) = ours(x)
        y_ref, h_ref = theirs(x)
    assert torch.allclose(y, y_ref, atol=1e-6) and torch.allclose(h, h_ref, atol=1e-6) and torch.equal(h, c)


def test_the_book_lstm_is_told_it_has_four_blocks():
    result = gru.check(gru.BASELINE)
    assert failed_with(result, ["four gate blocks per layer: an LSTM's", "cells[l] holds weight_x"]), str(result)


def test_students_unfinished_code_fails_without_raising():
    class Stub(nn.Module):                                  # the handed-out notebook's cells, untouched
        def __init__(self, input_size, hidden_size, num_layers=2):
            super().__init__()

        def forward(self, x, lengths=None, state=None):
            ...

        def step(self, x_t, state):
            ...

    class NoInit(nn.Module):
        def __init__(self, input_size, hidden_size, num_layers=2):
            pass

    assert failed_with(gru.check(Stub), ["0 parameters", "building a small PGAE with your layer raised"])
    assert failed_with(gru.check(NoInit), ["listing your layer's parameters raised"])


def test_the_run_returns_the_figures():
    figures = gru.run(gru.REFERENCE, seed=0, profile="smoke")
    assert set(figures) == set(gru.FIGURES)
    assert all(math.isfinite(v) for v in figures.values())
    with pytest.raises(ArgumentTypeError, match="builds the recurrent layer"):
        gru.run(None, profile="smoke")


# ------------------------------------------------------------------ the hook: pgae_lite.model.layers.recurrent_layers
def test_the_hook_builds_every_recurrent_layer_with_the_factory():
    cfg = ModelConfig(units=8)
    with recurrent_layers(gru.GRU):
        model = PGAE(cfg)
    assert all(type(getattr(model, p).rnn) is gru.GRU for p in PARTS)
    with recurrent_layers(PeepholeLSTM), recurrent_layers(gru.GRU):       # the innermost wins
        assert type(PGAE(cfg).action_encoder.rnn) is gru.GRU
    assert all(type(getattr(PGAE(cfg), p).rnn) is FusedLSTM for p in PARTS)   # and none after the block


def test_outside_the_hook_a_model_is_the_one_built_without_it():
    cfg = ModelConfig(units=8)
    torch.manual_seed(0)
    before = PGAE(cfg).state_dict()
    with pytest.raises(RuntimeError):                       # the block is left by an error
        with recurrent_layers(gru.GRU):
            raise RuntimeError
    torch.manual_seed(0)
    after = PGAE(cfg).state_dict()
    assert before.keys() == after.keys() and all(torch.equal(before[k], after[k]) for k in before)


def test_the_hook_refuses_what_is_no_factory():
    with pytest.raises(TypeError, match="factory"):
        with recurrent_layers(3):
            pass
    with pytest.raises(TypeError, match="returned int"):
        with recurrent_layers(lambda i, h, n: 3):
            PGAE(ModelConfig(units=8))
