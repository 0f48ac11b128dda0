"""PGAE for the reader's browser: one episode's forward pass as an ONNX graph (not in the paper).

Paper, Sec. 3: the two encoders, the GMU and the two decoders, unchanged. The page runs one
episode at a time, so the graph is PGAE's forward pass for a batch of one without padding:
every recurrent layer reads exactly the steps it reads in PyTorch (the language tokens up to
<EOS>, the action's first step or all of it, the decoder's steps), so there is no length to
mask, and the graph holds only the standard ONNX operators LSTM, Gemm, Tanh, Sigmoid, ...::

    language       (1, L) int64 tokens (PGAE's LSTM) or (1, D) float features (PGAE-BERT)
    action_input   (1, T_a, 35)   [v_t; j_t], the steps the signal shows the action encoder
    dec_vision     (1, S, 30)     v_t the action decoder reads, one per written step
    start          (1, 5)         the start joints
      -> logits (1, 4, 23), joints (1, S, 5), gate (1, hidden)     (normalised units)

:func:`episode_inputs` cuts one sample of a :class:`~pgae_lite.model.signals.SignalBatch` to
those steps; :func:`onnx_parity` runs the graph (onnxruntime) and PyTorch on the same samples.
"""
from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import torch
from torch import nn

from pgae_lite.model.layers import state_to_vector
from pgae_lite.model.pgae import PGAE
from pgae_lite.model.signals import SignalBatch
from pgae_lite.util.storage import atomic_write

INPUTS = ("language", "action_input", "dec_vision", "start")
OUTPUTS = ("logits", "joints", "gate")
OPSET = 17


class EpisodeGraph(nn.Module):
    """PGAE's forward pass for one episode without padding (what the page runs), same weights."""

    def __init__(self, model: PGAE):
        super().__init__()
        if model.cfg.joint_feedback != "start":
            raise ValueError("the browser graph needs joint_feedback='start' (the book recipe's): a decoder fed "
                             "its own predictions unrolls a loop whose length the graph would fix")
        model.eval()
        self.reads_tokens = not model.language_encoder.reads_free_text
        # PGAE-BERT's encoder is not part of the graph: the page gives its features (a table, or the
        # sentence encoder run in the page)
        self.language_encoder = model.language_encoder if self.reads_tokens else None
        self.action_encoder, self.gmu = model.action_encoder, model.gmu
        self.language_decoder, self.action_decoder = model.language_decoder, model.action_decoder

    def forward(self, language: torch.Tensor, action_input: torch.Tensor, dec_vision: torch.Tensor,
                start: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        # (1, 2 · layers · units) from tokens, or (1, D) features given
        f_lang = self.language_encoder(language, None) if self.reads_tokens else language
        k = self.action_encoder.stride
        _, state = self.action_encoder.rnn(action_input[:, ::k], None)       # every k-th step, all of them
        h, z = self.gmu(state_to_vector(state), f_lang)                       # h = z ⊙ A_h + (1 − z) ⊙ L_h
        logits = self.language_decoder(h)                                     # greedy, 4 words
        joints = self.action_decoder(h, dec_vision, start)                    # (1, S, 5), fused: no loop
        return logits, joints, z


def episode_inputs(batch: SignalBatch, i: int, language: torch.Tensor | None = None) -> dict[str, np.ndarray]:
    """Sample ``i`` of ``batch`` as the graph's inputs, cut to the steps it reads (``language``: PGAE-BERT's
    features of the whole batch, (B, D); else the tokens)."""
    steps = int(batch.joint_mask[i].sum())
    lang = batch.lang_tokens[i:i + 1, :int(batch.lang_lengths[i])] if language is None else language[i:i + 1]
    return {"language": lang.cpu().numpy(),
            "action_input": batch.action_input[i:i + 1, :int(batch.action_lengths[i])].cpu().numpy(),
            "dec_vision": batch.dec_vision[i:i + 1, :steps].cpu().numpy(),
            "start": batch.start_joints[i:i + 1].cpu().numpy()}


def to_onnx(model: PGAE, path: str | Path | None = None) -> bytes:
    """The model's :class:`EpisodeGraph` as ONNX bytes (written atomically to ``path`` if given)."""
    graph = EpisodeGraph(model).cpu().eval()      # eval: the exporter restores the mode it found (see below)
    language = (torch.tensor([[24, 14, 16, 19, 0]]) if graph.reads_tokens          # execute push red slowly
                else torch.zeros(1, model.language_encoder.output_dim))
    example = (language, torch.zeros(1, 4, 35), torch.zeros(1, 7, 30), torch.zeros(1, 5))
    dynamic = {"action_input": {1: "action_steps"}, "dec_vision": {1: "steps"}, "joints": {1: "steps"}}
    if graph.reads_tokens:
        dynamic["language"] = {1: "tokens"}
    out = io.BytesIO()
    with torch.no_grad():
        torch.onnx.export(graph, example, out, input_names=list(INPUTS), output_names=list(OUTPUTS),
                          dynamic_axes=dynamic, opset_version=OPSET, dynamo=False)
    data = out.getvalue()
    if path is not None:
        with atomic_write(path) as f:
            f.write(data)
    return data


@torch.no_grad()
def onnx_parity(model: PGAE, onnx_bytes: bytes, batch: SignalBatch, language: torch.Tensor | None = None) -> dict:
    """The graph (onnxruntime) against PyTorch's forward on every sample of ``batch``: the words (argmax of
    the logits) that differ, and the largest joint and gate differences, in the model's units."""
    import onnxruntime

    session = onnxruntime.InferenceSession(onnx_bytes, providers=["CPUExecutionProvider"])
    model.eval()
    ref = model(batch, language=language)
    words_differ, joints, gates = 0, 0.0, 0.0
    for i in range(len(batch.signal)):
        logits, out_joints, gate = session.run(list(OUTPUTS), episode_inputs(batch, i, language))
        steps = out_joints.shape[1]
        words_differ += int((logits[0].argmax(-1) != ref["logits"][i].argmax(-1).cpu().numpy()).any())
        joints = max(joints, float(np.abs(out_joints[0] - ref["joints"][i, :steps].cpu().numpy()).max()))
        gates = max(gates, float(np.abs(gate[0] - ref["gate"][i].cpu().numpy()).max()))
    return {"samples": len(batch.signal), "words_differ": words_differ, "max_joint_difference": joints,
            "max_gate_difference": gates}


__all__ = ["EpisodeGraph", "INPUTS", "OUTPUTS", "episode_inputs", "onnx_parity", "to_onnx"]
