"""pgae_lite.evaluate.table1: nRMSE, prediction conventions, Table 1."""
from __future__ import annotations

import math

import numpy as np
import pytest
import torch

from pgae_lite.config import ModelConfig
from pgae_lite.data.normaliser import Normaliser
from pgae_lite.evaluate.table1 import PAPER_TABLE, Predictions, evaluate, format_table, nrmse, predict
from pgae_lite.model.pgae import PGAE
from pgae_lite.world.patterns import Pattern
from pgae_lite.world.words import TEST_SIGNALS, WORD_INDEX


def _predictions(lengths, error, T=100):
    """Hand-made predictions: target 0.5 everywhere valid; prediction off by ``error`` on steps 1.."""
    n = len(lengths)
    mask = np.arange(T)[None, :, None] < np.asarray(lengths)[:, None, None]
    target = np.where(mask, 0.5, np.nan) * np.ones((n, T, 5))
    joints = target + error
    joints[:, 0] = target[:, 0]                                    # step 0 is given, not predicted
    return Predictions("execute", np.array([f"s{i}" for i in range(n)]), [""] * n, joints, target,
                       np.ones(n, bool), np.zeros((n, 50)))


def test_nrmse_known_value():
    p = _predictions([100, 50, 50], error=0.02)
    valid, padded = nrmse(p, joint_range=0.5)
    assert valid == pytest.approx(100 * 0.02 / 0.5)                # 4 %
    fraction = (99 + 49 + 49) / (3 * 99)                           # valid predicted steps
    assert padded == pytest.approx(valid * math.sqrt(fraction))


def test_nrmse_mixed_errors():
    p = _predictions([3, 2], error=0.0)
    p.joints[0, 1] += 0.3                                          # one step of sample 0, all 5 joints
    p.joints[0, 2, 0] += 0.4                                       # one joint
    valid, padded = nrmse(p, joint_range=2.0)
    mse = (5 * 0.3 ** 2 + 0.4 ** 2) / ((2 + 1) * 5)
    assert valid == pytest.approx(100 * math.sqrt(mse) / 2.0)
    assert padded == pytest.approx(100 * math.sqrt(mse * 15 / (2 * 99 * 5)) / 2.0)


def test_nrmse_perfect_is_zero():
    assert nrmse(_predictions([100, 50], 0.0), 1.0) == (0.0, 0.0)


@pytest.fixture(scope="module")
def tiny(toy):
    torch.manual_seed(0)
    model = PGAE(ModelConfig(units=16, joint_feedback="predicted")).eval()
    return model, Normaliser.fit(toy.split("train"))


def test_predict_conventions(toy, tiny):
    model, norm = tiny
    data = toy.subset(np.array([72, 0, 100, 1]))                   # lengths 50, 100, 50, 100
    for signal in ("execute", "describe", "repeat language"):
        p = predict(model, data, norm, signal)
        assert p.signal == signal
        assert p.joints.shape == p.target.shape == (4, 100, 5)
        assert p.joints.dtype == np.float32
        for k, n in enumerate(data.lengths):
            assert not np.isnan(p.joints[k, :n]).any() and np.isnan(p.joints[k, n:]).all()
            assert not np.isnan(p.target[k, :n]).any() and np.isnan(p.target[k, n:]).all()
        # Step 0 is the start pose in the data's own units.
        if signal == "execute":
            np.testing.assert_allclose(p.joints[:, 0], data.joints[:, 0], atol=1e-5)
            np.testing.assert_allclose(p.target[:, 1:3], data.joints[:, 1:3], atol=1e-5)
        elif signal == "describe":                                 # final pose, held
            last = data.joints[np.arange(4), data.lengths - 1]
            np.testing.assert_allclose(p.joints[:, 0], last, atol=1e-5)
        else:                                                      # first pose, held
            np.testing.assert_allclose(p.target[:, 5], data.joints[:, 0], atol=1e-5)
        assert list(p.ids) == list(data.ids)
        assert len(p.text) == 4 and p.gate.shape == (4, 50)


def test_predict_eos_only_gives_empty_text(toy, tiny):
    _, norm = tiny
    model = PGAE(ModelConfig(units=16, joint_feedback="predicted")).eval()
    with torch.no_grad():                                          # force <EOS> at every step
        model.language_decoder.out.weight.zero_()
        model.language_decoder.out.bias.zero_()
        model.language_decoder.out.bias[0] = 10.0
    data = toy.subset(np.arange(6))
    for signal in ("execute", "repeat action"):
        p = predict(model, data, norm, signal)
        assert p.text == [""] * 6 and p.correct.all()
    for signal in ("describe", "repeat language"):
        p = predict(model, data, norm, signal)
        assert p.text == [""] * 6 and not p.correct.any()


class _Says(torch.nn.Module):
    """A stand-in model that always generates the same words (and zero joints)."""

    def __init__(self, words):
        super().__init__()
        self.anchor = torch.nn.Parameter(torch.zeros(1))
        self.indices = [WORD_INDEX[w] for w in words] + [0] * (4 - len(words))

    def forward(self, batch):
        B, S = len(batch.signal), batch.joint_target.shape[1]
        logits = torch.nn.functional.one_hot(torch.tensor(self.indices), 23).float().expand(B, 4, 23)
        return {"logits": logits, "joints": torch.zeros(B, S, 5), "gate": torch.zeros(B, 50),
                "h": torch.zeros(B, 50)}


def test_predict_accepts_any_equivalent_description(toy, tiny):
    """Saying 'move-up scarlet unhurriedly' is correct on exactly the 'push red slowly' samples."""
    _, norm = tiny
    p = predict(_Says(["move-up", "scarlet", "unhurriedly"]), toy, norm, "describe")
    assert set(p.text) == {"move-up scarlet unhurriedly"}
    meaning = [(q.action, q.colour, q.speed) for q in map(Pattern.from_number, toy.pattern)]
    assert p.correct.tolist() == [m == ("push", "red", "slowly") for m in meaning]
    assert p.correct.sum() == 4                   # red+blue L, green+red R, blue+red R, red+green L
    wrong_length = predict(_Says(["push", "red"]), toy, norm, "describe")
    assert not wrong_length.correct.any()


def test_evaluate_returns_the_four_test_signals(toy, tiny):
    model, norm = tiny
    results, preds = evaluate(model, toy, norm)
    assert list(results) == list(TEST_SIGNALS)
    assert set(preds) == set(TEST_SIGNALS)
    for s in TEST_SIGNALS:
        r = results[s]
        assert set(r) == {"accuracy", "nrmse", "nrmse_padded", "n"}
        assert r["n"] == 36 and 0 <= r["accuracy"] <= 100
        assert 0 < r["nrmse_padded"] < r["nrmse"]
        assert preds[s].joints.shape == (36, 100, 5)
        assert set(preds[s].ids) == set(toy.ids[toy.is_test])


def test_format_table_has_the_papers_numbers(toy, tiny):
    results = {s: {"accuracy": 50.0, "nrmse": 1.0, "nrmse_padded": 0.9, "n": 36} for s in TEST_SIGNALS}
    text = format_table({"PGAE (ours)": results}, {"PGAE (ours)": "PGAE"})
    for number in ("93.05", "96.30", "100.00", "0.23", "0.37", "0.44"):
        assert number in text
    assert "PGAE (ours)" in text and "paper PGAE" in text
    for s in TEST_SIGNALS:
        assert s in text
    assert "93.05" not in format_table({"PGAE (ours)": results})       # no paper row unless asked


def test_paper_table_complete():
    assert set(PAPER_TABLE) == {"PGAE", "PGAE-BERT", "PGAE-self", "PGAE-opposite"}
    for row in PAPER_TABLE.values():
        assert set(row) == set(TEST_SIGNALS)
    assert PAPER_TABLE["PGAE-opposite"]["describe"] == (65.28, 2.40)
