"""PGAE-BERT's free text in the reader's browser: the sentence encoder as ONNX graphs (not in the paper).

Paper, Sec. 3: PGAE-BERT reads any text through a frozen pretrained transformer. In the page, one
graph holds the transformer below its top layer (shared by both PGAE-BERT models), and each model
has a head, its own top layer and pooling, that turns those token vectors into the features
PGAE's GMU reads::

    transformer   input_ids, attention_mask (1, L)  -> below_top (1, L, D)
    head          below_top (1, L, D), mask (1, L)  -> features (1, D_f)   the encoder's ``export_head()``:
                  the paper's PGAE-BERT: the pretrained top layer, then the mean over the tokens
                  the free-form variant: its tuned top layer, then its attention pooling

A batch of one has no padding, so every token is real. The page tokenizes with the same model's
tokenizer files (``tokenizer.json``). The weights are stored in half precision (:func:`half_weights`:
42 MB instead of 84 MB for all-MiniLM-L6-v2's layers below the top) and computed in float32.
:func:`sentence_parity` runs the graphs with onnxruntime against the encoder itself.
"""
from __future__ import annotations

import io

import numpy as np
import torch
from torch import nn

from pgae_lite.bert.pretrained import input_text
from pgae_lite.model.signals import make_batch, signal_ids
from pgae_lite.util.storage import atomic_write
from pgae_lite.world.words import decode


class TransformerGraph(nn.Module):
    """The frozen transformer below its top layer: the hidden states the top layer reads."""

    def __init__(self, transformer: nn.Module):
        super().__init__()
        self.transformer = transformer.eval()

    def forward(self, input_ids: torch.Tensor, attention_mask: torch.Tensor) -> torch.Tensor:
        out = self.transformer(input_ids=input_ids, attention_mask=attention_mask, output_hidden_states=True)
        return out.hidden_states[-2]               # the top layer's output is not used: the export drops it


def _export(module: nn.Module, example: tuple, names: list[str], outputs: list[str], dynamic: dict) -> bytes:
    # In eval mode: the exporter puts the module back in the mode it found it in, and a new wrapper is in
    # training mode, which would switch the shared transformer's dropout on for the rest of the process.
    module.eval()
    out = io.BytesIO()
    with torch.no_grad():
        torch.onnx.export(module, example, out, input_names=names, output_names=outputs, dynamic_axes=dynamic,
                          opset_version=17, dynamo=False)
    return out.getvalue()


def half_weights(data: bytes, smallest: int = 1024) -> bytes:
    """An ONNX graph with its float32 weights of ``smallest`` values or more stored as float16.

    Each such weight W becomes W16 (float16) and a node ``W = Cast(W16, float32)`` at the graph's start,
    so every operator still computes in float32 (the browser's WebAssembly kernels are float32):
    only the rounding of the weights to float16 changes the result."""
    import onnx
    from onnx import TensorProto, helper, numpy_helper

    model = onnx.load_from_string(data)
    graph, casts = model.graph, []
    for weight in list(graph.initializer):
        if weight.data_type == TensorProto.FLOAT and int(np.prod(weight.dims)) >= smallest:
            half = numpy_helper.from_array(numpy_helper.to_array(weight).astype(np.float16), weight.name + "_fp16")
            casts.append(helper.make_node("Cast", [half.name], [weight.name], to=TensorProto.FLOAT))
            graph.initializer.remove(weight)
            graph.initializer.append(half)
    nodes = casts + list(graph.node)                     # the casts first: the graph's nodes are in order
    del graph.node[:]
    graph.node.extend(nodes)
    return model.SerializeToString()


def transformer_onnx(transformer: nn.Module, path=None, half: bool = True) -> bytes:
    """The transformer graph as ONNX bytes (weights in float16 if ``half``), written to ``path`` if given."""
    ids = torch.tensor([[101, 7592, 2088, 102]])
    data = _export(TransformerGraph(transformer), (ids, torch.ones_like(ids)), ["input_ids", "attention_mask"],
                   ["below_top"], {"input_ids": {1: "tokens"}, "attention_mask": {1: "tokens"},
                                   "below_top": {1: "tokens"}})
    # Deviation from paper: the page's transformer has float16 weights (half the bytes; see sentence_parity)
    data = half_weights(data) if half else data
    if path is not None:
        with atomic_write(path) as f:
            f.write(data)
    return data


def head_onnx(encoder: nn.Module, path=None, half: bool = True) -> bytes:
    """One PGAE-BERT model's head (its language encoder's ``export_head()``) as ONNX bytes (weights in float16
    if ``half``), written to ``path`` if given."""
    head = encoder.export_head()
    if head is None:
        raise ValueError(f"{type(encoder).__name__} reads no free text: it has no head for the page")
    D = encoder.transformer.model.config.hidden_size
    example = (torch.zeros(1, 4, D), torch.ones(1, 4, dtype=torch.long))
    data = _export(head, example, ["below_top", "mask"], ["features"],
                   {"below_top": {1: "tokens"}, "mask": {1: "tokens"}})
    data = half_weights(data) if half else data
    if path is not None:
        with atomic_write(path) as f:
            f.write(data)
    return data


def sentence_features(encoder: nn.Module, transformer_bytes: bytes, head_bytes: bytes, signal: str,
                      texts: list[str]) -> np.ndarray:
    """The features of ``texts`` under ``signal`` as the page computes them, with onnxruntime (N, D).

    As ``encoder.encode_texts`` reads them: the text after its word lookup, the signal phrase first; a text
    the tuned variant was trained on comes from its table (it reads it through its frozen top layer)."""
    import onnxruntime

    run = [onnxruntime.InferenceSession(b, providers=["CPUExecutionProvider"]) for b in (transformer_bytes, head_bytes)]
    tokenizer, fixed = encoder.transformer.tokenizer, {text: i for i, text in enumerate(encoder.texts)}
    out = []
    for text in texts:
        read = input_text(signal, encoder.read_as(text))
        if encoder.fixed_from_table and read in fixed:
            with torch.no_grad():
                out.append(encoder.encode_texts([read]).cpu().numpy()[0])
            continue
        enc = tokenizer([read], truncation=True, return_tensors="np")
        ids, mask = enc["input_ids"].astype(np.int64), enc["attention_mask"].astype(np.int64)
        (below,) = run[0].run(None, {"input_ids": ids, "attention_mask": mask})
        (features,) = run[1].run(None, {"below_top": below, "mask": mask})
        out.append(features[0])
    return np.stack(out).astype(np.float32)


def sentence_parity(encoder: nn.Module, transformer_bytes: bytes, head_bytes: bytes, signal: str,
                    texts: list[str]) -> dict:
    """The graphs (onnxruntime) against ``encoder.encode_texts`` on ``texts`` under ``signal``: the largest
    feature difference, and that difference relative to the features' own spread."""
    features = sentence_features(encoder, transformer_bytes, head_bytes, signal, texts)
    with torch.no_grad():
        ref = encoder.encode_texts([input_text(signal, text) for text in texts]).cpu().numpy()
    worst, spread = float(np.abs(features - ref).max()), float(np.abs(ref).max())
    return {"texts": len(texts), "max_difference": worst, "relative": worst / spread if spread else 0.0}


@torch.no_grad()
def free_text_reference(model: nn.Module, normaliser, test, texts: list[str], rows: list[int] | None = None
                        ) -> list[dict]:
    """What PyTorch computes for ``texts[i]`` typed on test episode ``rows[i]`` (default ``i mod N``) under
    execute, as :func:`~pgae_lite.robot.playground.play` computes it (what the page must give): the words,
    the readback under repeat language, and the joints in the data's units (steps, 5), step 0 the start.
    (Whether the robot acts on the text is :func:`pgae_lite.freeform.refusals.refusal`'s to say.)"""
    model.eval()
    tensors = normaliser.tensors(test)
    rows = torch.arange(len(texts)) % len(test) if rows is None else torch.as_tensor(rows)
    said = {}
    for signal in ("execute", "repeat language"):
        batch = make_batch(tensors, rows, signal_ids(signal, len(texts)), torch.zeros(len(texts), dtype=torch.long))
        language = model.language_encoder.encode_texts([input_text(signal, text) for text in texts])
        said[signal] = model(batch, language=language), batch
    (out, batch), (back, _) = said["execute"], said["repeat language"]
    joints = normaliser.joints_to_data(torch.cat([batch.start_joints[:, None], out["joints"]], 1))   # (B, T, 5)
    return [{"episode": str(test.ids[int(r)]), "words": decode(out["logits"][i].argmax(-1)),
             "understood": decode(back["logits"][i].argmax(-1)),
             "joints": joints[i, :int(test.lengths[int(r)])].cpu().numpy()} for i, r in enumerate(rows)]


__all__ = ["TransformerGraph", "free_text_reference", "half_weights", "head_onnx", "sentence_features",
           "sentence_parity", "transformer_onnx"]
