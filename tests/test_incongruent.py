"""Incongruent input (pgae_lite/evaluate/incongruent.py): the swaps are what they say, the measures Table 1's."""
from __future__ import annotations

import numpy as np
import pytest

from pgae_lite.evaluate.incongruent import meanings, shown_instead, swapped_words
from pgae_lite.world.patterns import pattern_parts
from pgae_lite.world.words import CANONICAL, VOCABULARY, WORD_INDEX


def words(*w):
    return np.array([WORD_INDEX[x] for x in w])


@pytest.mark.parametrize("kind, slot", [("action", 0), ("colour", 1), ("speed", 2)])
def test_one_word_is_swapped_for_another_of_its_slot_and_a_synonym_stays_one(kind, slot):
    rng = np.random.default_rng(0)
    for read in (words("push", "red", "slowly"), words("move-up", "scarlet", "unhurriedly")):
        for _ in range(20):
            out = swapped_words(read, kind, rng)
            changed = [i for i in range(3) if out[i] != read[i]]
            assert changed == [slot]
            old, new = VOCABULARY[read[slot]], VOCABULARY[out[slot]]
            assert CANONICAL[new] != CANONICAL[old] and (new == CANONICAL[new]) == (old == CANONICAL[old])
    assert ("move-down", "red", "quickly") in meanings(words("pull", "scarlet", "fast"))


@pytest.mark.parametrize("kind", ["action", "position", "speed"])
def test_the_recording_shown_differs_from_the_sample_by_its_kind_alone(toy, kind):
    test = np.flatnonzero(toy.is_test)
    shown = shown_instead(toy, test, kind, np.random.default_rng(0))
    for i, j in zip(test, shown):
        (s0, a0, x0), (s1, a1, x1) = pattern_parts(int(toy.pattern[i])), pattern_parts(int(toy.pattern[j]))
        differs = {"speed": s0 != s1, "verb": x0 % 3 != x1 % 3, "side": x0 // 3 != x1 // 3}
        assert a0 == a1                                                  # the same scene
        assert differs == {"speed": kind == "speed", "verb": kind == "action", "side": kind == "position"}


def test_the_joint_error_is_table_1s(toy_tensors, toy):
    """One nRMSE in the book: the incongruent cells' and the closed loop's are Table 1's (evaluate.table1)."""
    from pgae_lite.evaluate import incongruent
    from pgae_lite.evaluate.table1 import Predictions, joint_nrmse, nrmse
    from pgae_lite.robot import closedloop

    rng = np.random.default_rng(1)
    target = toy.joints[:10]
    joints = target + rng.normal(0, 0.01, target.shape)
    mask = toy.mask[:10]
    pred = Predictions("execute", toy.ids[:10], [""] * 10, np.where(mask[..., None], joints, np.nan),
                       np.where(mask[..., None], target, np.nan), np.zeros(10, bool), np.zeros((10, 0)))
    assert incongruent._nrmse(joints, target, mask, 2.0) == nrmse(pred, 2.0)[0]
    length = int(mask[0].sum())
    assert closedloop._nrmse(joints[0], target[0], length, 2.0) == joint_nrmse(joints[:1, :length],
                                                                                target[:1, :length], 2.0)[0]
