"""Limited supervision (pgae_lite/train/supervision.py): which steps are paired, in both readings."""
from __future__ import annotations

import pytest
import torch

from pgae_lite.model.signals import SIGNAL_PROBS, sample_signals
from pgae_lite.train.config import TrainConfig
from pgae_lite.train.supervision import PAIRED, UNIMODAL, SupervisionConfig, draw_signals, labelled_samples, restricted


def test_within_each_kind_a_signal_keeps_its_weight():
    assert restricted(SIGNAL_PROBS, PAIRED) == pytest.approx((3 / 7, 3 / 7, 0, 1 / 7, 0))
    assert restricted(SIGNAL_PROBS, UNIMODAL) == pytest.approx((0, 0, 1 / 2, 0, 1 / 2))
    with pytest.raises(ValueError, match="no weight to any of the signals"):
        restricted((0.5, 0.5, 0, 0, 0), UNIMODAL)


def test_the_recipe_draws_exactly_what_it_drew_before():
    """Neither share set: the same draws from the same generator, so every model trained before is the same."""
    ours, before = torch.Generator().manual_seed(3), torch.Generator().manual_seed(3)
    for _ in range(20):
        assert torch.equal(draw_signals(16, ours, TrainConfig()), sample_signals(16, before))


@pytest.mark.parametrize("share", [0.02, 0.2, 0.5])
def test_a_share_of_the_updates_is_paired_whole(share):
    cfg, gen = TrainConfig(supervision=SupervisionConfig(share)), torch.Generator().manual_seed(0)
    kinds = []
    for _ in range(4000):
        signals = set(draw_signals(16, gen, cfg).tolist())
        assert signals <= set(PAIRED) or signals <= set(UNIMODAL)       # a batch is one kind
        kinds.append(signals <= set(PAIRED))
    assert sum(kinds) / len(kinds) == pytest.approx(share, abs=4 * (share * (1 - share) / 4000) ** 0.5)


def test_a_fixed_share_of_the_samples_is_labelled_and_only_those_are_paired():
    labelled = labelled_samples(200, 0.05, seed=1)
    assert labelled.sum().item() == 10 and torch.equal(labelled, labelled_samples(200, 0.05, seed=1))
    assert not torch.equal(labelled, labelled_samples(200, 0.05, seed=2))
    assert labelled_samples(30, 0.02, seed=0).sum().item() == 1                 # never none
    cfg, gen = TrainConfig(supervision=SupervisionConfig(0.05, of="samples")), torch.Generator().manual_seed(0)
    seen_paired = torch.zeros(200, dtype=torch.bool)
    for _ in range(300):
        index = torch.randperm(200, generator=gen)[:16]
        signals = draw_signals(16, gen, cfg, labelled[index])
        paired = torch.isin(signals, torch.tensor(PAIRED))
        assert not paired[~labelled[index]].any()                            # an unlabelled sample: unimodal only
        seen_paired[index[paired]] = True
    assert torch.equal(seen_paired, labelled)                                 # and every labelled one is paired


@pytest.mark.parametrize("change, message", [
    ({"share": 0.0}, r"SupervisionConfig share must be a number in \(0, 1\], the paired share; got 0.0"),
    ({"share": 1.5, "of": "samples"}, r"SupervisionConfig share must be a number in \(0, 1\]"),
    ({"share": 0.2, "of": "both"}, "SupervisionConfig of must be one of updates, samples"),
])
def test_a_wrong_share_is_refused(change, message):
    """One part, one reading of limited supervision (the old paired_share and labelled_share at once: no more)."""
    with pytest.raises(ValueError, match=message):
        TrainConfig(supervision=SupervisionConfig(**change))


def test_a_training_on_a_labelled_subset_runs_and_is_seeded(toy_short):
    from pgae_lite.config import get_profile
    from pgae_lite.train.loop import train

    prof = get_profile("smoke", epochs=2, supervision=SupervisionConfig(0.1, of="samples"))
    first = train(toy_short, prof, device="cpu", progress=False)
    second = train(toy_short, prof, device="cpu", progress=False)
    assert first.history == second.history
    plain = train(toy_short, get_profile("smoke", epochs=2), device="cpu", progress=False)
    assert plain.history != first.history
