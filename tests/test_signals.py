"""pgae_lite.model.signals: each signal's encoder inputs and decoder targets (BRIEF §2 table)."""
from __future__ import annotations

import pytest
import torch

from pgae_lite.model.signals import (
    DESCRIBE,
    EXECUTE,
    REPEAT_ACTION,
    REPEAT_BOTH,
    REPEAT_LANGUAGE,
    SIGNAL_PROBS,
    make_batch,
    sample_signals,
    signal_ids,
)
from pgae_lite.world.words import SIGNALS, VOCABULARY

# A fast (50-step) and a slow (100-step) sample of the toy set, and another fast one.
INDEX = torch.tensor([72, 0, 100])

#            language in, whole action in, description out, joints held
TABLE = {
    "describe":        (False, True,  True,  "last"),
    "execute":         (True,  False, False, None),
    "repeat action":   (False, True,  False, None),
    "repeat both":     (True,  True,  True,  None),
    "repeat language": (True,  False, True,  "first"),
}


def _batch(tensors, signal, alternative=(3, 0, 7), opposite=None):
    sig = signal_ids(signal, len(INDEX))
    opp = None if opposite is None else torch.full((len(INDEX),), opposite)
    return make_batch(tensors, INDEX, sig, torch.tensor(alternative), opp)


def test_indices_fixed():
    assert (DESCRIBE, EXECUTE, REPEAT_ACTION, REPEAT_BOTH, REPEAT_LANGUAGE) == tuple(
        SIGNALS.index(s) for s in ("describe", "execute", "repeat action", "repeat both", "repeat language"))
    assert signal_ids("repeat_language", 3).tolist() == [4, 4, 4]
    assert signal_ids(["describe", "Execute"]).tolist() == [0, 1]


@pytest.mark.parametrize("signal", SIGNALS)
def test_make_batch_follows_the_table(toy_tensors, signal):
    lang_in, action_in, lang_out, held = TABLE[signal]
    alternative = torch.tensor([3, 0, 7])
    b = _batch(toy_tensors, signal, alternative.tolist())
    s = SIGNALS.index(signal)
    B, T = len(INDEX), 100
    lengths = toy_tensors["lengths"][INDEX]
    assert lengths.tolist() == [50, 100, 50]
    words = toy_tensors["descriptions"][INDEX, alternative]                  # (B, 3)
    joints, vision = toy_tensors["joints"][INDEX], toy_tensors["vision"][INDEX]

    assert b.signal.tolist() == [s] * B
    # Language encoder: signal token 23 + s, then words + <EOS>, or <EOS> alone.
    assert (b.lang_tokens[:, 0] == len(VOCABULARY) + s).all()
    if lang_in:
        assert torch.equal(b.lang_tokens[:, 1:4], words)
        assert (b.lang_tokens[:, 4] == 0).all()
        assert b.lang_lengths.tolist() == [5] * B
    else:
        assert (b.lang_tokens[:, 1] == 0).all()
        assert b.lang_lengths.tolist() == [2] * B
    # Action encoder: [vision; joints], whole or first step only.
    assert b.action_input.shape == (B, T, 35)
    torch.testing.assert_close(b.action_input, torch.cat([vision, joints], 2))
    assert b.action_lengths.tolist() == (lengths.tolist() if action_in else [1] * B)
    # Language decoder target.
    assert b.lang_target.shape == b.lang_mask.shape == (B, 4)
    if lang_out:
        assert torch.equal(b.lang_target[:, :3], words) and (b.lang_target[:, 3] == 0).all()
        assert b.lang_mask.all()
    else:
        assert (b.lang_target == 0).all()
        assert b.lang_mask[:, 0].all() and not b.lang_mask[:, 1:].any()
    # Action decoder: start joints, target joints of steps 1.., mask, vision.
    assert b.joint_target.shape == (B, T - 1, 5) and b.dec_vision.shape == (B, T - 1, 30)
    expected_mask = torch.arange(1, T)[None] < lengths[:, None]
    assert torch.equal(b.joint_mask, expected_mask)
    for k, n in enumerate(lengths.tolist()):
        if held is None:
            torch.testing.assert_close(b.start_joints[k], joints[k, 0])
            torch.testing.assert_close(b.joint_target[k], joints[k, 1:])
            torch.testing.assert_close(b.dec_vision[k], vision[k, :-1])
        else:
            step = n - 1 if held == "last" else 0
            torch.testing.assert_close(b.start_joints[k], joints[k, step])
            torch.testing.assert_close(b.joint_target[k], joints[k, step].expand(T - 1, 5))
            torch.testing.assert_close(b.dec_vision[k], vision[k, step].expand(T - 1, 30))


@pytest.mark.parametrize("signal", ["describe", "repeat action", "repeat both"])
def test_opposite_view(toy_tensors, signal):
    b = _batch(toy_tensors, signal, opposite=True)
    own = _batch(toy_tensors, signal, opposite=False)
    joints = toy_tensors["joints"][INDEX]
    opp_vision = toy_tensors["vision_opposite"][INDEX]
    torch.testing.assert_close(b.action_input[..., :30], opp_vision)
    torch.testing.assert_close(b.action_input[..., 30:], joints[:, :1].expand_as(joints))   # NICO's first joints, held
    assert torch.equal(b.action_lengths, own.action_lengths)
    torch.testing.assert_close(b.lang_tokens, own.lang_tokens)
    if signal == "describe":     # NICO has not moved: its target is its first pose, held
        first = joints[:, 0]
        torch.testing.assert_close(b.start_joints, first)
        torch.testing.assert_close(b.joint_target, first[:, None].expand(-1, 99, -1))
    else:                        # the decoder still produces NICO's own sequence
        torch.testing.assert_close(b.joint_target, own.joint_target)
        torch.testing.assert_close(b.dec_vision, own.dec_vision)


def test_mixed_signals_in_one_batch(toy_tensors):
    """Every sample of a batch may have its own signal: each row equals a one-signal batch's row."""
    index = torch.tensor([72, 0, 100, 1, 73])
    signal = torch.tensor([DESCRIBE, EXECUTE, REPEAT_ACTION, REPEAT_BOTH, REPEAT_LANGUAGE])
    alternative = torch.tensor([1, 2, 3, 4, 5])
    opposite = torch.tensor([True, False, False, True, False])
    mixed = make_batch(toy_tensors, index, signal, alternative, opposite)
    for k in range(5):
        single = make_batch(toy_tensors, index[k:k + 1], signal[k:k + 1], alternative[k:k + 1],
                            opposite[k:k + 1])
        for name, value in vars(mixed).items():
            if value is None:                                    # a training's field (the plan's targets)
                assert getattr(single, name) is None, (k, name)
            else:
                assert torch.equal(value[k:k + 1], getattr(single, name)), (k, name)


def test_sample_signals_frequencies():
    gen = torch.Generator().manual_seed(0)
    s = sample_signals(90_000, gen)
    freq = torch.bincount(s, minlength=5).float() / len(s)
    assert freq.tolist() == pytest.approx([1 / 3, 1 / 3, 1 / 9, 1 / 9, 1 / 9], abs=0.01)
    assert SIGNAL_PROBS == pytest.approx((1 / 3, 1 / 3, 1 / 9, 1 / 9, 1 / 9))
    assert sum(SIGNAL_PROBS) == pytest.approx(1.0)


def test_sample_signals_per_batch():
    gen = torch.Generator().manual_seed(0)
    firsts = []
    for _ in range(900):
        s = sample_signals(6, gen, per_sample=False)
        assert s.shape == (6,) and (s == s[0]).all()
        firsts.append(int(s[0]))
    freq = torch.bincount(torch.tensor(firsts), minlength=5).float() / 900
    assert freq.tolist() == pytest.approx([1 / 3, 1 / 3, 1 / 9, 1 / 9, 1 / 9], abs=0.06)


def test_sample_signals_deterministic():
    a = sample_signals(50, torch.Generator().manual_seed(3))
    b = sample_signals(50, torch.Generator().manual_seed(3))
    assert torch.equal(a, b)
