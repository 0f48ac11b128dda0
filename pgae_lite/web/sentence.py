"""PGAE-BERT's free text in the reader's browser: the sentence encoder as ONNX graphs (not in the paper).

Paper, Sec. 3: PGAE-BERT reads any text through a frozen pretrained transformer. In the page, one
graph holds the transformer (shared by both PGAE-BERT models), and each model has a small head
that turns its token vectors into the features PGAE's GMU reads::

    transformer   input_ids, attention_mask (1, L)    -> last (1, L, D), below_top (1, L, D)
    head          last, below_top (1, L, D), mask (1, L) -> features (1, D_f)
                  the paper's PGAE-BERT: the mean of ``last`` over the tokens
                  the free-form variant: its tuned top layer on ``below_top``, then its attention pooling

A batch of one has no padding, so every token is real. :func:`sentence_parity` runs the graphs with
onnxruntime against the encoder itself. The page is to tokenize with the same model's tokenizer
files (``tokenizer.json``).
"""
from __future__ import annotations

import io

import numpy as np
import torch
from torch import nn

from pgae_lite.bert.pretrained import input_text
from pgae_lite.util.storage import atomic_write


class TransformerGraph(nn.Module):
    """The frozen transformer: the last hidden states and those below the top layer."""

    def __init__(self, transformer: nn.Module):
        super().__init__()
        self.transformer = transformer.eval()

    def forward(self, input_ids: torch.Tensor, attention_mask: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        out = self.transformer(input_ids=input_ids, attention_mask=attention_mask, output_hidden_states=True)
        return out.last_hidden_state, out.hidden_states[-2]


class HeadGraph(nn.Module):
    """One PGAE-BERT model's features from the token vectors of one text (no padding)."""

    def __init__(self, encoder: nn.Module):
        super().__init__()
        self.top = getattr(encoder, "top", None)
        self.attention = getattr(encoder, "attention", None)      # the variant's attention pooling
        if self.attention is None and getattr(encoder, "pooling", "mean") != "mean":
            raise ValueError(f"the page pools tokens by their mean; this encoder pools by {encoder.pooling!r}")

    def forward(self, last: torch.Tensor, below_top: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
        if self.attention is None:                                          # the paper's: the mean
            weight = mask[..., None].float()                                # (1, L, 1)
            return (last * weight).sum(1) / weight.sum(1)                   # f = Σ_t x_t / L
        states = last if self.top is None else self.top(below_top, mask.bool())   # the tuned top layer
        return self.attention(states, mask.bool())                          # f = 1/K Σ_k Σ_t a_tk x_t


def _export(module: nn.Module, example: tuple, names: list[str], outputs: list[str], dynamic: dict) -> bytes:
    # In eval mode: the exporter puts the module back in the mode it found it in, and a new wrapper is in
    # training mode, which would switch the shared transformer's dropout on for the rest of the process.
    module.eval()
    out = io.BytesIO()
    with torch.no_grad():
        torch.onnx.export(module, example, out, input_names=names, output_names=outputs, dynamic_axes=dynamic,
                          opset_version=17, dynamo=False)
    return out.getvalue()


def transformer_onnx(transformer: nn.Module, path=None) -> bytes:
    """The transformer graph as ONNX bytes (float32), written to ``path`` if given."""
    ids = torch.tensor([[101, 7592, 2088, 102]])
    data = _export(TransformerGraph(transformer), (ids, torch.ones_like(ids)), ["input_ids", "attention_mask"],
                   ["last", "below_top"], {"input_ids": {1: "tokens"}, "attention_mask": {1: "tokens"},
                                           "last": {1: "tokens"}, "below_top": {1: "tokens"}})
    if path is not None:
        with atomic_write(path) as f:
            f.write(data)
    return data


def head_onnx(encoder: nn.Module, path=None) -> bytes:
    """One PGAE-BERT model's :class:`HeadGraph` as ONNX bytes, written to ``path`` if given."""
    D = encoder.transformer.model.config.hidden_size
    example = (torch.zeros(1, 4, D), torch.zeros(1, 4, D), torch.ones(1, 4, dtype=torch.long))
    data = _export(HeadGraph(encoder), example, ["last", "below_top", "mask"], ["features"],
                   {"last": {1: "tokens"}, "below_top": {1: "tokens"}, "mask": {1: "tokens"}})
    if path is not None:
        with atomic_write(path) as f:
            f.write(data)
    return data


def sentence_parity(encoder: nn.Module, transformer_bytes: bytes, head_bytes: bytes, signal: str,
                    texts: list[str]) -> dict:
    """The graphs (onnxruntime) against ``encoder.encode_texts`` on ``texts`` under ``signal``: the largest
    feature difference, and that difference relative to the features' own spread."""
    import onnxruntime

    run = [onnxruntime.InferenceSession(b, providers=["CPUExecutionProvider"]) for b in (transformer_bytes, head_bytes)]
    tokenizer = encoder.transformer.tokenizer
    worst, spread = 0.0, 0.0
    for text in texts:
        read = input_text(signal, encoder.read_as(text))
        enc = tokenizer([read], truncation=True, return_tensors="np")
        ids, mask = enc["input_ids"].astype(np.int64), enc["attention_mask"].astype(np.int64)
        last, below = run[0].run(None, {"input_ids": ids, "attention_mask": mask})
        wanted = {i.name for i in run[1].get_inputs()}                     # the mean head reads no below_top
        (features,) = run[1].run(None, {k: v for k, v in (("last", last), ("below_top", below), ("mask", mask))
                                        if k in wanted})
        with torch.no_grad():
            ref = encoder.encode_texts([input_text(signal, text)]).cpu().numpy()
        worst = max(worst, float(np.abs(features - ref).max()))
        spread = max(spread, float(np.abs(ref).max()))
    return {"texts": len(texts), "max_difference": worst, "relative": worst / spread if spread else 0.0}


__all__ = ["HeadGraph", "TransformerGraph", "head_onnx", "sentence_parity", "transformer_onnx"]
