"""The chapters' plotting and table helpers: right content, figures returned, nothing shown."""

import matplotlib

matplotlib.use("Agg")  # before pyplot is imported anywhere in this process

import numpy as np
import pytest
import torch
from matplotlib.figure import Figure

from pgae_lite.data import Normaliser
from pgae_lite.evaluate import Predictions
from pgae_lite.language import SIGNALS
from pgae_lite.signals import make_batch
from pgae_lite.toydata import toy_dataset
from pgae_lite.viz import (plot_gates, plot_history, plot_joints, plot_vision, prediction_frame,
                           signal_table, wrong_words)


@pytest.fixture(scope="module")
def toy():
    data = toy_dataset(variations=1)
    train = data.split("train")
    return data, train, Normaliser.fit(train).tensors(train)


def test_signal_table_reads_the_five_signals(toy):
    _, train, tensors = toy
    fast = int(np.flatnonzero(train.lengths == 50)[0])
    batch = make_batch(tensors, torch.full((5,), fast), torch.arange(5), torch.zeros(5, dtype=torch.long))
    table = signal_table(batch)
    assert list(table.index) == list(SIGNALS)
    assert table.loc["describe", "language input"] == "[describe] <EOS>"
    assert table.loc["execute", "action input"] == "first step only"
    assert table.loc["repeat action", "action input"] == "whole sequence (50 steps)"
    assert table.loc["execute", "language target"] == "<EOS>"
    assert table.loc["describe", "action target"].startswith("final pose, held")
    assert table.loc["repeat language", "action target"].startswith("first pose, held")
    assert table.loc["repeat both", "action target"] == "recorded sequence, 50 steps"


def test_wrong_words_treats_synonyms_as_equal():
    assert wrong_words("push red slowly", "move-up scarlet unhurriedly") == ""
    assert wrong_words("push red slowly", "move-up blue slowly") == "colour"
    assert wrong_words("push red slowly", "pull red fast") == "action, speed"
    assert wrong_words("push red slowly", "") == "<EOS> only"
    assert wrong_words("", "push") == "1 word"


def test_prediction_frame(toy):
    data, _, _ = toy
    test = data.split("test")
    n = len(test)
    text = ["" for _ in range(n)]
    pred = Predictions("describe", test.ids, text, np.zeros((n, 100, 5)), np.zeros((n, 100, 5)),
                       np.zeros(n, dtype=bool), np.zeros((n, 50)))
    frame = prediction_frame(pred, test)
    assert len(frame) == n and set(frame.action) == {"push", "pull", "slide"}
    assert set(frame.side) == {"left cube", "right cube"} and (frame.wrong == "<EOS> only").all()
    eos = prediction_frame(Predictions("execute", test.ids, text, pred.joints, pred.target,
                                       np.ones(n, dtype=bool), pred.gate), test)
    assert (eos.expected == "").all() and (eos.wrong == "").all()


def test_plots_return_figures():
    history = [{"epoch": e, "loss": 1.0 / e, "language_loss": 0.9 / e, "action_loss": 0.1 / e,
                "gate": {s: 0.5 for s in SIGNALS}} for e in (1, 2, 3)]
    joints = np.random.default_rng(0).random((100, 5))
    figures = [plot_gates({s: np.full((4, 50), 0.3) for s in SIGNALS}), plot_history(history),
               plot_joints(joints, joints, 50, "t"), plot_vision(np.zeros((100, 30)), 50)]
    assert all(isinstance(f, Figure) for f in figures)
