"""Lab 3, the new task (describing what the opposite agent does): the check passes the reference and names each
wrong component; the lab's training batches are the package's make_batch with the opposite view on describe;
the lab's run gives its figures (smoke profile)."""
from __future__ import annotations

import math

import torch

from pgae_lite.course.labs import lab as lab_module
from pgae_lite.course.labs import opposite_task as lab
from pgae_lite.data.normaliser import Normaliser
from pgae_lite.data.toy import toy_dataset
from pgae_lite.model.config import ModelConfig
from pgae_lite.model.signals import DESCRIBE, make_batch
from pgae_lite.train.config import TrainConfig
from pgae_lite.train.draws import Draws
from pgae_lite.world.words import DEFAULT_LEXICON


def test_the_lab_has_every_name_a_lab_has():
    assert lab_module("opposite_task") is lab


def test_the_reference_passes_on_other_seeds_and_sizes():
    for seed, batch, steps in ((0, 6, 12), (1, 9, 100), (2, 2, 3)):
        result = lab.check(lab.REFERENCE, seed=seed, batch=batch, steps=steps)
        assert result, str(result)


def test_the_untouched_handout_and_other_mistakes_are_named():
    def untouched(vision, vision_opposite, joints, lengths):
        ...

    assert "a stub returns None" in str(lab.check(untouched))

    def swapped(vision, vision_opposite, joints, lengths):
        action_input, held = lab.REFERENCE(vision, vision_opposite, joints, lengths)
        return torch.cat([action_input[..., 30:], action_input[..., :30]], 2), held

    assert "the layout is [vision; joints]" in str(lab.check(swapped))

    def in_place(vision, vision_opposite, joints, lengths):
        joints[:, 1:] = joints[:, :1]
        return lab.REFERENCE(vision, vision_opposite, joints, lengths)

    assert "changed joints in place" in str(lab.check(in_place))


def test_padding_is_never_judged():
    def zero_padding(vision, vision_opposite, joints, lengths):
        action_input, held = lab.REFERENCE(vision, vision_opposite, joints, lengths)
        valid = (torch.arange(joints.shape[1])[None] < lengths[:, None])[..., None]
        return action_input * valid, held * valid

    assert lab.check(zero_padding)


def test_the_lab_batches_are_the_packages_with_the_opposite_view_on_describe():
    toy = toy_dataset(1, 0, patterns=[0, 7, 80, 101, 140, 3, 9, 44])
    data = Normaliser.fit(toy).tensors(toy)
    recipe = TrainConfig(opposite_prob=0.5, input_noise=0.0, joint_input_noise=None)
    torch.manual_seed(0)
    model = lab.TaskPGAE(ModelConfig(units=8, hidden=6), DEFAULT_LEXICON, lab.REFERENCE)
    index = torch.arange(len(toy))
    got = model.training_batch(data, index, Draws(recipe, torch.Generator().manual_seed(3)))
    draws = Draws(recipe, torch.Generator().manual_seed(3))
    signal, alternative = draws.signals(index), draws.descriptions(len(index))
    opposite = draws.views(len(index)) & (signal == DESCRIBE)
    expected = make_batch(data, index, signal, alternative, opposite)
    assert opposite.any() and (signal != DESCRIBE).any()
    for name in ("signal", "lang_tokens", "action_input", "action_lengths", "lang_target", "dec_vision",
                 "start_joints", "joint_target", "joint_mask"):
        assert torch.equal(getattr(got, name), getattr(expected, name)), name


def test_the_run_gives_the_figures_with_and_without_the_task():
    for task in (lab.REFERENCE, lab.BASELINE):
        figures = lab.run(task, seed=0, profile="smoke")
        assert set(figures) == set(lab.FIGURES)
        assert all(math.isfinite(v) and 0 <= v <= 100 for v in figures.values())
