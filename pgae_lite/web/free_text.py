"""The files free text needs in the reader's browser, written at build time (not in the paper).

Paper, Sec. 3: PGAE-BERT reads any text. For the page to read it as Python does, the build writes,
next to the playground's models (:mod:`pgae_lite.web.assets`)::

    models/transformer.onnx      the transformer below its top layer, float16 weights (sentence.py)
    models/NAME.head.onnx        each PGAE-BERT model's top layer and pooling (sentence.py)
    models/NAME.words.json       the free-form variant's word lookup as a table (word_table.py)
    models/NAME.refusals.json    each model's reading of what it refuses (refusal_data.py)
    refusals.json                the refusal rule's words, shared (refusal_data.py)
    tokenizer/tokenizer.json     the transformer's tokenizer, without its vocabulary ...
    tokenizer/vocab.txt          ... which is here, one token per line, in the order of its ids
    tokenizer/tokenizer_config.json

The page fetches them on a reader's first free text only (``book/_js/pgae.js``). Every file is
written without indentation: free text is to fit in 50 MB.
"""
from __future__ import annotations

import json
import tempfile
from pathlib import Path

from pgae_lite.util.storage import atomic_write_text, make_folder
from pgae_lite.web.refusal_data import front_coded, model_reading, shared_words
from pgae_lite.web.sentence import head_onnx, transformer_onnx
from pgae_lite.web.word_table import word_table


def _compact(value) -> str:
    return json.dumps(value, ensure_ascii=False, separators=(",", ":"))


def _tokenizer(tokenizer, folder: Path) -> None:
    """The fast tokenizer's own files, its vocabulary split out as plain lines (half the bytes)."""
    make_folder(folder)
    with tempfile.TemporaryDirectory() as tmp:
        tokenizer.save_pretrained(tmp)
        saved = json.loads((Path(tmp) / "tokenizer.json").read_text(encoding="utf-8"))
        config = json.loads((Path(tmp) / "tokenizer_config.json").read_text(encoding="utf-8"))
    vocab = saved["model"].pop("vocab")                                # token -> id
    tokens = sorted(vocab, key=vocab.get)
    if [vocab[t] for t in tokens] != list(range(len(tokens))) or any("\n" in t for t in tokens):
        raise ValueError("the page reads the vocabulary as lines in the order of the ids: this tokenizer's "
                         "ids are not 0, 1, 2, ... or a token holds a line break")
    atomic_write_text(folder / "vocab.txt", "\n".join(tokens))
    atomic_write_text(folder / "tokenizer.json", _compact(saved))
    atomic_write_text(folder / "tokenizer_config.json", _compact(config))


def export_free_text(out: Path, encoders: dict, entries: dict, half: bool = True) -> dict:
    """Write the files above for the PGAE-BERT models ``encoders`` (name -> language encoder); add each
    model's files to its ``entries[name]``; return what the manifest says of the shared ones.
    ``half=False``: the weights in float32 (twice the bytes, past the page's 50 MB budget; the page then
    computes what Python computes to float32 rounding, where float16 weights can tip a near tie)."""
    names = {encoder.name for encoder in encoders.values()}
    if len(names) != 1:
        raise ValueError(f"the page holds one sentence encoder, but the models read {sorted(names)}")
    encoder = next(iter(encoders.values()))
    transformer_onnx(encoder.transformer.model, out / "models" / "transformer.onnx", half=half)
    _tokenizer(encoder.transformer.tokenizer, out / "tokenizer")
    shared = shared_words()
    atomic_write_text(out / "refusals.json", _compact(shared | {"verbs": front_coded(shared["verbs"])}))
    for name, encoder in encoders.items():
        head_onnx(encoder, out / "models" / f"{name}.head.onnx", half=half)
        atomic_write_text(out / "models" / f"{name}.refusals.json", _compact(model_reading(encoder, shared)))
        entries[name] |= {"head": f"models/{name}.head.onnx", "words": None,
                          "refusals": f"models/{name}.refusals.json",
                          # the tuned variant reads a text it was trained on from its frozen table (encode_texts)
                          "fixed_from_table": encoder.fixed_from_table}
        if encoder.word_lookup is not None:
            atomic_write_text(out / "models" / f"{name}.words.json", _compact(word_table(encoder.word_lookup)))
            entries[name]["words"] = f"models/{name}.words.json"
    files = ["models/transformer.onnx", "refusals.json", "tokenizer/tokenizer.json", "tokenizer/vocab.txt",
             "tokenizer/tokenizer_config.json"]
    files += [entry[k] for entry in entries.values() for k in ("head", "words", "refusals") if entry.get(k)]
    return {"transformer": files[0], "refusals": files[1], "tokenizer": files[2], "vocab": files[3],
            "tokenizer_config": files[4], "max_tokens": int(min(encoder.transformer.tokenizer.model_max_length, 512)),
            "bytes": sum((out / f).stat().st_size for f in files), "weights": "float16" if half else "float32"}


__all__ = ["export_free_text"]
