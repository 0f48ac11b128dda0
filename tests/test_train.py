"""pgae_lite.train.loop and pgae_lite.config: learning, determinism, checkpoints, resuming, profiles."""
from __future__ import annotations

import math
import os
from dataclasses import replace

import numpy as np
import pytest
import torch

from pgae_lite.config import PROFILE_ENV, PROFILES, ModelConfig, Profile, TrainConfig, get_profile
from pgae_lite.data.normaliser import Normaliser
from pgae_lite.evaluate.table1 import predict
from pgae_lite.model.loss import pgae_loss
from pgae_lite.runs.pipeline import load_model
from pgae_lite.train.checkpoint import CHECKPOINT, DataMismatchError, load_checkpoint
from pgae_lite.train.loop import train
from pgae_lite.train.optimiser import lr_factor


def tiny_profile(units: int = 16, **train) -> Profile:
    """12 training samples, batches of 4, a few epochs: a second or two of training.

    No plan head (plan.py): with 12 samples each is its own pattern, and a few hundred steps are
    spent on the words; tests/test_plan.py trains the head.
    """
    cfg = replace(TrainConfig(), epochs=4, batch_size=4, lr=3e-3, max_train_samples=12, checkpoint_every=1,
                  action_weight=1.0, input_noise=0.05, joint_input_noise=None)
    return Profile("tiny", ModelConfig(units=units, joint_feedback="predicted", plan_keyframes=0),
                   replace(cfg, **train))


def _weights(model):
    return {k: v.detach().clone() for k, v in model.state_dict().items()}


def _same_weights(a, b) -> bool:
    return a.keys() == b.keys() and all(torch.equal(a[k], b[k]) for k in a)


# --------------------------------------------------------------------------- learning
def test_learns_a_handful_of_samples(toy_short):
    """12 samples: the loss falls, joints are fitted, and <EOS> is learnt for execute / repeat action.

    (Generating their descriptions 100% right takes thousands of optimiser steps with the current
    recipe, far more than a unit test may spend, so description accuracy is not asserted here.)
    """
    # (60 epochs: at 40, <EOS> was learnt on some seeds and not on others, with or without length batches)
    prof = tiny_profile(units=32, epochs=60, lr=1e-2)
    trained = train(toy_short, prof, progress=False, device="cpu")
    h = trained.history
    assert len(h) == 60 and [r["epoch"] for r in h] == list(range(1, 61))
    first = h[0]
    # Each epoch draws new signals for its 12 samples, so single epochs are noisy: average the last 5.
    assert np.mean([r["loss"] for r in h[-5:]]) < 0.7 * first["loss"]
    assert np.mean([r["action_loss"] for r in h[-5:]]) < 0.4 * first["action_loss"]
    samples = toy_short.split("train").subset(slice(0, 12))
    for signal in ("execute", "repeat action"):
        assert predict(trained.model, samples, trained.normaliser, signal).correct.all(), signal
    assert not trained.model.training
    assert trained.seconds > 0


def test_normaliser_from_training_samples_only(toy_short):
    trained = train(toy_short, tiny_profile(epochs=1), progress=False, device="cpu")
    assert trained.normaliser == Normaliser.fit(toy_short.split("train").subset(slice(0, 12)), "whiten")


def test_history_records(toy_short):
    trained = train(toy_short, tiny_profile(epochs=2), progress=False, device="cpu")
    rec = trained.history[-1]
    assert set(rec) >= {"epoch", "loss", "language_loss", "action_loss", "lr", "gate"}
    assert rec["loss"] == pytest.approx(rec["language_loss"] + rec["action_loss"], rel=1e-5)
    assert set(rec["gate"]) <= {"describe", "execute", "repeat action", "repeat both", "repeat language"}
    assert all(0 < g < 1 for g in rec["gate"].values())


# --------------------------------------------------------------------------- determinism
def test_same_seed_same_run_different_seed_different_run(toy_short):
    a = train(toy_short, tiny_profile(epochs=3), progress=False, device="cpu")
    b = train(toy_short, tiny_profile(epochs=3), progress=False, device="cpu")
    c = train(toy_short, tiny_profile(epochs=3, seed=1), progress=False, device="cpu")
    assert a.history == b.history
    assert _same_weights(_weights(a.model), _weights(b.model))
    assert a.history != c.history
    assert not _same_weights(_weights(a.model), _weights(c.model))


def test_the_callers_thread_count_does_not_change_the_model(toy_short, set_threads):
    """A training runs on utils.TRAINING_THREADS, whatever the caller set, and gives it back."""
    runs = []
    for threads in (1, 2):              # the book's sizes: big enough for torch to split its sums
        set_threads(threads)
        runs.append(train(toy_short, tiny_profile(units=100, epochs=2), progress=False, device="cpu"))
        assert torch.get_num_threads() == threads
    assert runs[0].history == runs[1].history
    assert _same_weights(_weights(runs[0].model), _weights(runs[1].model))


# --------------------------------------------------------------------------- checkpoints
def test_checkpoint_round_trip(toy_short, tmp_path):
    prof = tiny_profile(epochs=2)
    trained = train(toy_short, prof, out_dir=tmp_path, progress=False, device="cpu")
    assert (tmp_path / CHECKPOINT).is_file()
    assert not list(tmp_path.glob("*.tmp"))
    model, norm, ckpt = load_model(tmp_path / CHECKPOINT, device="cpu")
    assert not model.training
    assert norm == trained.normaliser
    assert ckpt["epoch"] == 2 and ckpt["history"] == trained.history and ckpt["profile"] == prof.to_dict()
    assert _same_weights(_weights(model), _weights(trained.model))
    test = toy_short.split("test").subset(slice(0, 8))
    for signal in ("describe", "execute"):
        p, q = predict(trained.model, test, trained.normaliser, signal), predict(model, test, norm, signal)
        assert p.text == q.text
        np.testing.assert_array_equal(p.joints, q.joints)


def test_finished_run_returns_at_once(toy_short, tmp_path):
    prof = tiny_profile(epochs=2)
    first = train(toy_short, prof, out_dir=tmp_path, progress=False, device="cpu")
    calls = []
    again = train(toy_short, prof, out_dir=tmp_path, progress=False, device="cpu",
                  callback=lambda *a: calls.append(a))
    assert calls == []                                            # no epoch was run again
    assert again.history == first.history
    assert _same_weights(_weights(again.model), _weights(first.model))


def test_the_progress_bar_names_its_model_and_a_finished_model_shows_none(toy_short, tmp_path, capsys):
    prof = tiny_profile(epochs=2)
    train(toy_short, prof, out_dir=tmp_path, progress=True, device="cpu", name="PGAE-BERT")
    assert "PGAE-BERT (" in capsys.readouterr().err                  # the bar of the training, named
    train(toy_short, prof, out_dir=tmp_path, progress=True, device="cpu", name="PGAE-BERT")
    assert "PGAE-BERT (" not in capsys.readouterr().err              # loaded from the cache: no bar


def test_resume_after_interruption_is_identical(toy_short, tmp_path, interrupt_training):
    """Stopping at epoch 3 of 5 (no checkpoint for it) and training again gives the same run."""
    prof = tiny_profile(epochs=5)
    whole = train(toy_short, prof, out_dir=tmp_path / "whole", progress=False, device="cpu")

    interrupt_training(toy_short, prof, tmp_path / "cut", epoch=3)
    assert load_checkpoint(tmp_path / "cut" / CHECKPOINT)["epoch"] == 2
    epochs_run = []
    resumed = train(toy_short, prof, out_dir=tmp_path / "cut", progress=False, device="cpu",
                    callback=lambda epoch, *_: epochs_run.append(epoch))
    assert epochs_run == [3, 4, 5]
    assert resumed.history == whole.history
    assert _same_weights(_weights(resumed.model), _weights(whole.model))


def test_resume_with_sparse_checkpoints(toy_short, tmp_path, interrupt_training):
    """checkpoint_every=2: an interruption at epoch 4 resumes from epoch 2."""
    prof = tiny_profile(epochs=5, checkpoint_every=2)
    whole = train(toy_short, prof, progress=False, device="cpu")

    interrupt_training(toy_short, prof, tmp_path, epoch=4)
    assert load_checkpoint(tmp_path / CHECKPOINT)["epoch"] == 2
    resumed = train(toy_short, prof, out_dir=tmp_path, progress=False, device="cpu")
    assert resumed.history == whole.history
    assert _same_weights(_weights(resumed.model), _weights(whole.model))


def test_checkpoint_of_another_profile_is_refused(toy_short, tmp_path):
    train(toy_short, tiny_profile(epochs=1), out_dir=tmp_path, progress=False, device="cpu")
    with pytest.raises(ValueError, match="different profile"):
        train(toy_short, tiny_profile(epochs=1, seed=7), out_dir=tmp_path, progress=False, device="cpu")


def test_load_checkpoint_is_weights_only(tmp_path):
    path = tmp_path / "evil.pt"
    torch.save({"model": {}, "payload": os.system}, path)         # an arbitrary pickled object
    with pytest.raises(Exception, match="(?i)weights.only"):
        load_checkpoint(path)


# --------------------------------------------------------------------------- loss
def test_pgae_loss_by_hand(toy_tensors):
    from pgae_lite.model.signals import make_batch, signal_ids
    from pgae_lite.world.words import word_weights
    b = make_batch(toy_tensors, torch.tensor([72, 0]), signal_ids(["describe", "execute"]), torch.tensor([0, 0]))
    torch.manual_seed(0)
    out = {"logits": torch.randn(2, 4, 23), "joints": torch.randn(2, 99, 5)}
    w = word_weights()
    total, lang, act = pgae_loss(out, b, w, alpha=2.0, beta=3.0)
    logp = out["logits"].log_softmax(-1)
    terms = [(w[b.lang_target[i, t]] * -logp[i, t, b.lang_target[i, t]])
             for i in range(2) for t in range(4) if b.lang_mask[i, t]]
    assert len(terms) == 5                                          # 4 words of describe, <EOS> of execute
    assert float(lang) == pytest.approx(float(sum(terms) / 5), rel=1e-5)
    sq = [((out["joints"][i, t] - b.joint_target[i, t]) ** 2).mean() for i in range(2) for t in range(99)
          if b.joint_mask[i, t]]
    assert len(sq) == 49 + 99
    assert float(act) == pytest.approx(float(sum(sq) / len(sq)), rel=1e-5)
    assert float(total) == pytest.approx(2 * float(lang) + 3 * float(act), rel=1e-5)


# --------------------------------------------------------------------------- profiles
def test_profiles():
    assert set(PROFILES) == {"smoke", "book", "paper"}
    paper = get_profile("paper")
    assert paper.model.cell == "peephole" and paper.train.lr == 1e-5 and paper.train.batch_size == 6
    assert paper.train.epochs == 6000 and not paper.train.signals_per_sample
    assert paper.train.language_weight == paper.train.action_weight == 1.0   # the paper's α = β = 1
    book = get_profile("book")
    assert book.train == TrainConfig() and book.model == ModelConfig()        # the defaults are the book recipe
    assert book.train.epochs < paper.train.epochs and book.train.lr > paper.train.lr
    p = get_profile("smoke", seed=3, epochs=7)
    assert p.train.seed == 3 and p.train.epochs == 7
    assert PROFILES["smoke"].train.seed == 0 and PROFILES["smoke"].train.epochs == 3   # built-ins untouched
    assert p.to_dict()["model"]["units"] == 32


def test_profile_from_environment(monkeypatch):
    monkeypatch.setenv(PROFILE_ENV, "smoke")
    assert get_profile().name == "smoke"
    monkeypatch.delenv(PROFILE_ENV)
    assert get_profile().name == "book"


def test_unknown_profile_and_option():
    with pytest.raises(ValueError) as e:
        get_profile("fast")
    assert "'fast'" in str(e.value) and all(n in str(e.value) for n in ("smoke", "book", "paper"))
    with pytest.raises(ValueError) as e:
        get_profile("smoke", learning_rate=1.0)
    assert "learning_rate" in str(e.value)
    for name in ("lr", "epochs", "batch_size", "seed"):
        assert name in str(e.value)


def test_lr_factor_warmup_then_cosine():
    total, warmup = 1000, 0.1
    f = [lr_factor(s, total, warmup, "cosine") for s in range(total)]
    assert f[0] == pytest.approx(1 / 100) and f[49] == pytest.approx(0.5) and f[99] == pytest.approx(1.0)
    assert all(b > a for a, b in zip(f[:99], f[1:100]))            # linear warm-up
    assert f[100] == pytest.approx(1.0)
    assert all(b <= a for a, b in zip(f[100:], f[101:]))           # then decreasing
    assert f[550] == pytest.approx(0.5, abs=1e-9)                  # half-way down the cosine
    assert f[325] == pytest.approx(0.5 * (1 + math.cos(math.pi * 0.25)))
    assert 0 <= f[-1] < 1e-4
    assert lr_factor(total + 5, total, warmup, "cosine") == 0.0     # past the end: 0, not rising again
    assert [lr_factor(s, total, warmup, "constant") for s in (0, 99, 100, 999)] == \
        pytest.approx([0.01, 1.0, 1.0, 1.0])
    assert lr_factor(0, total, 0.0, "cosine") == 1.0                 # no warm-up


def test_signal_probs_choose_the_signals_drawn(toy_short):
    """signal_probs=0 for a signal: it is never drawn (the gate log names only drawn signals)."""
    no_both = (0.375, 0.375, 0.125, 0.0, 0.125)
    run = train(toy_short, tiny_profile(epochs=3, signal_probs=no_both), progress=False)
    drawn = set().union(*(r["gate"] for r in run.history))
    assert "repeat both" not in drawn and {"describe", "execute"} <= drawn
    assert run.profile.train.signal_probs == no_both


@pytest.mark.parametrize("probs", [(0.5, 0.5), (0.5, 0.5, 0.5, 0.0, 0.0), (1.2, -0.2, 0.0, 0.0, 0.0)])
def test_bad_signal_probs_say_what_is_allowed(probs):
    with pytest.raises(ValueError, match="5 non-negative numbers summing to 1.*describe, execute"):
        get_profile("smoke", signal_probs=probs)


def test_input_noise_changes_training_and_stays_deterministic(toy_short):
    """Noise on the action encoder's inputs: another run than without, the same run twice."""
    clean = train(toy_short, tiny_profile(epochs=2, input_noise=0.0), progress=False, device="cpu")
    noisy = [train(toy_short, tiny_profile(epochs=2, input_noise=0.05), progress=False, device="cpu")
             for _ in range(2)]
    assert noisy[0].history == noisy[1].history
    assert noisy[0].history != clean.history
    paper = get_profile("paper").train
    assert paper.input_noise == 0.0 and paper.joint_input_noise is None   # the paper's recipe has none
    joints_only = train(toy_short, tiny_profile(epochs=2, input_noise=0.0, joint_input_noise=0.05),
                        progress=False, device="cpu")
    assert joints_only.history != clean.history                  # noise on the joints alone counts too


def test_add_input_noise_separates_vision_and_joints():
    from pgae_lite.train.draws import add_input_noise
    x = torch.zeros(4, 100, 35)
    torch.manual_seed(0)
    both = add_input_noise(x, 0.05)
    assert 0.045 < both[..., :30].std() < 0.055 and 0.045 < both[..., 30:].std() < 0.055
    vision_only = add_input_noise(x, 0.05, joint_std=0.0)
    assert vision_only[..., 30:].abs().max() == 0            # the joints stay exact
    assert 0.045 < vision_only[..., :30].std() < 0.055
    torch.manual_seed(0)
    assert torch.equal(add_input_noise(x, 0.05, joint_std=None), both)   # None: the same std on both


def test_whitening_is_saved_with_the_model(toy_short, tmp_path):
    trained = train(toy_short, tiny_profile(epochs=1, vision_scaling="whiten"), out_dir=tmp_path,
                    progress=False, device="cpu")
    assert trained.normaliser.whitening is not None
    _, normaliser, _ = load_model(tmp_path / "checkpoint.pt", "cpu")
    assert normaliser == trained.normaliser
    with pytest.raises(ValueError, match="global, whiten"):
        tiny_profile(vision_scaling="each")
    assert get_profile("book").train.vision_scaling == "whiten"
    assert get_profile("paper").train.vision_scaling == "global"          # the authors' one min/max


def test_a_model_refuses_data_it_was_not_trained_on(toy_short, tmp_path):
    train(toy_short, tiny_profile(epochs=1, vision_scaling="whiten"), out_dir=tmp_path, progress=False, device="cpu")
    load_model(tmp_path / CHECKPOINT, "cpu", toy_short)                    # its own data: accepted
    other_cae = replace(toy_short, vision=toy_short.vision + 0.01)         # as if another CAE made the features
    with pytest.raises(DataMismatchError, match="PGAE_LITE_CACHE") as err:
        load_model(tmp_path / CHECKPOINT, "cpu", other_cae)
    assert "whitening" in str(err.value)                                # what differs is named
    with pytest.raises(DataMismatchError, match="another output folder"):  # nor resumes or reuses it
        train(other_cae, tiny_profile(epochs=1, vision_scaling="whiten"), out_dir=tmp_path, progress=False,
              device="cpu")


def test_weight_decay_uses_adamw(toy_short):
    plain = train(toy_short, tiny_profile(epochs=2, weight_decay=0.0), progress=False, device="cpu")
    decayed = train(toy_short, tiny_profile(epochs=2, weight_decay=0.1), progress=False, device="cpu")
    assert decayed.history != plain.history
    assert get_profile("paper").train.weight_decay == 0.0


# --------------------------------------------------------------------------- one loop for every model
def test_the_loop_builds_the_model_its_recipe_describes(toy_short):
    """No model is named: the recipe's parts say which model the loop builds, and every one trains the same way."""
    from pgae_lite.model.pgae import PGAE
    from pgae_lite.model.prae import PRAE
    from pgae_lite.model.ptae import PTAE
    from pgae_lite.model.pvae import PVAE
    from pgae_lite.runs.rows import TRAININGS

    base = tiny_profile(epochs=1)
    built = {name: train(toy_short, TRAININGS[name].profile(base), progress=False, device="cpu")
             for name in ("PGAE", "PTAE", "PRAE", "PVAE")}
    assert {name: type(t.model) for name, t in built.items()} == {"PGAE": PGAE, "PTAE": PTAE, "PRAE": PRAE,
                                                                  "PVAE": PVAE}
    for name in ("PGAE", "PTAE"):
        assert set(built[name].history[-1]) == {"epoch", "loss", "language_loss", "action_loss", "lr", "gate"}
    assert "gate" in built["PGAE"].history[-1] and built["PTAE"].history[-1]["gate"] == {}   # PTAE has no GMU
    assert set(built["PVAE"].history[-1]) - set(built["PRAE"].history[-1]) == {"kl"}
    assert all(not t.model.training and t.profile.model == TRAININGS[n].profile(base).model for n, t in built.items())
    mine = PGAE(ModelConfig(units=8, plan_keyframes=0))                     # a model given: not built
    assert train(toy_short, base, progress=False, device="cpu", model=mine).model is mine


def test_the_loop_takes_a_profile_not_a_name(toy_short):
    with pytest.raises(TypeError, match="train takes a Profile, e.g. pgae_lite.config.get_profile"):
        train(toy_short, "smoke", progress=False, device="cpu")
