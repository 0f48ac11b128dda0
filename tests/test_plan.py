"""pgae_lite.model.plan: the plan head's targets, loss and training, and models without it."""
from __future__ import annotations

from dataclasses import replace

import pytest
import torch

from pgae_lite.config import PROFILES, ModelConfig, Profile, TrainConfig
from pgae_lite.model.pgae import PGAE
from pgae_lite.model.plan import PLAN_SIGNALS, keyframe_steps, plan_loss, plan_targets
from pgae_lite.model.signals import DESCRIBE, EXECUTE, REPEAT_LANGUAGE
from pgae_lite.train.loop import train


def test_keyframes_span_each_sample():
    steps = keyframe_steps(torch.tensor([100, 50, 10]), 10)
    assert steps[:, 0].tolist() == [0, 0, 0]
    assert steps[:, -1].tolist() == [99, 49, 9]
    assert (steps.diff(dim=1) > 0).all()


def test_targets_are_the_pattern_mean():
    joints = torch.zeros(4, 6, 5)
    joints[0] = 1.0                      # pattern 7, twice: mean of 1 and 3
    joints[1] = 3.0
    joints[2, :, 0] = torch.arange(6.0)  # pattern 2, alone: its own keyframes
    joints[3] = -1.0                     # pattern 9
    lengths = torch.tensor([6, 6, 6, 4])
    target = plan_targets(joints, lengths, torch.tensor([7, 7, 2, 9]), keyframes=3).reshape(4, 3, 5)
    assert torch.allclose(target[0], torch.full((3, 5), 2.0)) and torch.equal(target[0], target[1])
    assert target[2, :, 0].tolist() == [0.0, 2.0, 5.0]      # steps 0, round(2.5) = 2, 5
    assert torch.equal(target[3], torch.full((3, 5), -1.0))


def test_loss_counts_only_signals_that_execute_a_motion():
    plan, target = torch.zeros(3, 10), torch.ones(3, 10)
    assert plan_loss(plan, target, torch.tensor([DESCRIBE, REPEAT_LANGUAGE, DESCRIBE])).item() == 0.0
    assert plan_loss(plan, target, torch.tensor([DESCRIBE, EXECUTE, REPEAT_LANGUAGE])).item() == 1.0
    assert EXECUTE in PLAN_SIGNALS and DESCRIBE not in PLAN_SIGNALS


def test_paper_profile_has_no_plan_head():
    assert PGAE(PROFILES["paper"].model).plan_head is None
    assert PROFILES["paper"].train.plan_weight == 0
    assert PGAE(PROFILES["book"].model).plan_head is not None


@pytest.mark.parametrize("bad", [-1, 2.5, True, "10"])
def test_bad_keyframe_count_is_a_clear_error(bad):
    with pytest.raises(ValueError, match="plan_keyframes must be a whole number"):
        ModelConfig(plan_keyframes=bad)


def test_head_learns_the_plan(toy_short):
    """A few epochs on 24 samples: the plan head's error falls, and the model keeps the head in eval."""
    cfg = replace(TrainConfig(), epochs=30, batch_size=8, lr=3e-3, max_train_samples=24, checkpoint_every=30,
                  plan_weight=4.0)
    prof = Profile("tiny-plan", ModelConfig(units=16, plan_keyframes=4), cfg)
    trained = train(toy_short, prof, progress=False, device="cpu")
    data = trained.normaliser.tensors(toy_short.split("train").subset(slice(0, 24)))
    target = plan_targets(data["joints"], data["lengths"],
                          torch.as_tensor(toy_short.split("train").pattern[:24]), 4)
    fresh = PGAE(prof.model)
    from pgae_lite.model.signals import make_batch, signal_ids
    index = torch.arange(24)
    batch = make_batch(data, index, signal_ids("execute", 24), index % 8)
    with torch.no_grad():
        before = plan_loss(fresh(batch)["plan"], target, batch.signal)
        after = plan_loss(trained.model(batch)["plan"], target, batch.signal)
    assert after < 0.5 * before


def test_probe_reads_what_is_linearly_there_and_not_what_is_not():
    from pgae_lite.model.plan import probe_accuracy

    g = torch.Generator().manual_seed(0)
    x, x_test = torch.randn(1000, 50, generator=g), torch.randn(200, 50, generator=g)
    y, y_test = (x[:, 3] > 0).long(), (x_test[:, 3] > 0).long()      # one dimension says it
    assert probe_accuracy(x, y, x_test, y_test) >= 95.0
    noise = torch.randint(2, (200,), generator=g)                    # labels h cannot know
    assert 30.0 < probe_accuracy(x, torch.randint(2, (1000,), generator=g), x_test, noise) < 70.0


def test_which_cube_probe_runs_on_a_model(toy_short):
    from pgae_lite.data.normaliser import Normaliser
    from pgae_lite.model.plan import which_cube_probe

    normaliser = Normaliser.fit(toy_short.split("train"))
    accuracy = which_cube_probe(PGAE(ModelConfig(units=16)), toy_short, normaliser)
    assert 0.0 <= accuracy <= 100.0
