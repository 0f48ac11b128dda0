"""Lab 2, the CAE's channel widths: the check passes the reference and names each wrong component; the CAE's
hook for another autoencoder leaves the book's CAE as it was; the lab's run gives its figures (smoke profile)."""
from __future__ import annotations

import math

import numpy as np
import pytest
import torch
from torch import nn

from pgae_lite.cae import CAEConfig, ChannelAutoencoder, ChannelSeparatedCAE, train_cae
from pgae_lite.course.labs import cae_widths as lab
from pgae_lite.course.labs import lab as lab_module

FRAMES = np.random.default_rng(0).integers(0, 256, (8, 120, 160, 3), dtype=np.uint8)


def test_the_lab_has_every_name_a_lab_has():
    assert lab_module("cae_widths") is lab
    assert lab.WIDTHS == tuple(w // 2 for w in CAEConfig().conv)


def test_the_reference_passes_and_the_book_is_not_the_change():
    result = lab.check(lab.REFERENCE)
    assert result, str(result)
    assert lab.check(lab.REFERENCE, seed=3, batch=5)
    assert not lab.check(lab.BASELINE)


class Untouched(nn.Module):
    """The handout's class, as a student receives it: every body `...`."""

    def __init__(self):
        super().__init__()

    def encode(self, x):
        ...

    def logits(self, z):
        ...

    def forward(self, x):
        ...


def test_the_untouched_handout_fails_with_words():
    result = lab.check(Untouched)
    assert not result and "encode(x) of 3 images gave None" in str(result), str(result)
    assert "raised" in str(lab.check(lambda: 1 / 0)) and not lab.check(lambda: 1 / 0)


def test_a_student_module_without_the_methods_is_told_which():
    result = lab.check(lambda: nn.Linear(2, 2))
    assert not result and "lacks encode, logits" in str(result), str(result)


def test_the_hook_leaves_the_book_cae_bit_identical():
    config = CAEConfig("tiny", batch_size=4, iterations=3, seed=0)
    torch.manual_seed(0)
    a = ChannelSeparatedCAE(config).state_dict()
    torch.manual_seed(0)
    b = ChannelSeparatedCAE(config, ChannelAutoencoder).state_dict()
    assert all(torch.equal(a[k], b[k]) for k in a)
    _, plain = train_cae(FRAMES, config, device="cpu", progress=False)
    _, hooked = train_cae(FRAMES, config, device="cpu", progress=False, autoencoder=ChannelAutoencoder)
    assert plain == hooked


def test_the_hook_trains_another_autoencoder_and_never_saves_it(tmp_path):
    config = CAEConfig("tiny", conv=lab.WIDTHS, batch_size=4, iterations=2, seed=0)
    model, history = train_cae(FRAMES, config, device="cpu", progress=False,
                               autoencoder=lambda _config: lab.REFERENCE())
    assert len(history) == 2 and isinstance(model.red, lab.REFERENCE)
    with pytest.raises(ValueError, match="out_path=None"):
        train_cae(FRAMES, config, progress=False, out_path=tmp_path / "cae.pt", autoencoder=ChannelAutoencoder)


def test_the_run_gives_the_figures_and_the_same_numbers_for_a_seed():
    figures = lab.run(lab.REFERENCE, seed=0, profile="smoke")
    assert set(figures) == set(lab.FIGURES)
    assert all(math.isfinite(v) for v in figures.values())
    assert 0 < figures["heldout_bce"] < 1 and figures["parameters"] == pytest.approx(3 * 518.715)
    again = lab.run(lab.REFERENCE, seed=0, profile="smoke")
    assert again["heldout_bce"] == figures["heldout_bce"]
