"""Checkpoints of a training: written atomically, read safely, checked against the data (paper Sec. 4).

A checkpoint holds the model's weights (with whatever its language encoder keeps beside them,
e.g. the free-form variant's word lookup), the optimiser, the random generators, the history,
the recipe (``Profile.to_dict()``, with its version) and the normaliser fitted on the training
samples: :func:`pgae_lite.runs.pipeline.load_model` rebuilds the same model from it
(:func:`check_recipe_version`, :func:`load_weights`), and refuses data it was not trained on.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import torch
from torch import nn

from pgae_lite.data.dataset import PGAEDataset
from pgae_lite.data.normaliser import Normaliser
from pgae_lite.train.config import RECIPE_VERSION
from pgae_lite.util.errors import PGAELiteError
from pgae_lite.util.storage import CheckpointMismatchError, load_state, load_torch, save_torch

CHECKPOINT = "checkpoint.pt"
#: What every checkpoint written by :func:`save_checkpoint` holds.
CHECKPOINT_KEYS = ("model", "optimiser", "generator", "torch_rng", "epoch", "history",
                   "profile", "normaliser", "seconds")
#: What a saved model needs to be used (:func:`pgae_lite.runs.pipeline.load_model`): not the optimiser's state.
MODEL_KEYS = ("model", "profile", "normaliser")
#: What must hold finite numbers only: the weights, the optimiser's state, the data statistics.
FINITE_KEYS = ("model", "optimiser", "normaliser")


class DataMismatchError(PGAELiteError, ValueError):
    """A checkpoint is used with data (visual features) other than those it was trained on."""


def training_split(dataset: PGAEDataset, max_samples: int | None = None) -> PGAEDataset:
    """The samples a training run learns from: the training split, or its first ``max_samples``."""
    train_set = dataset.split("train")
    return train_set.subset(slice(0, max_samples)) if max_samples else train_set


def save_checkpoint(path: Path, model: nn.Module, optimiser: torch.optim.Optimizer, gen: torch.Generator,
                    epoch: int, history: list[dict], profile, normaliser: Normaliser,
                    seconds: float) -> None:
    """Write a checkpoint atomically (a crash mid-write never leaves a broken file).

    A write that fails (a full disk, a read-only folder) raises
    :class:`~pgae_lite.util.atomic_files.OutputError` naming the file; the old checkpoint stays.
    """
    save_torch({"model": model.state_dict(), "optimiser": optimiser.state_dict(),
                "generator": gen.get_state(), "torch_rng": torch.get_rng_state(),
                "epoch": epoch, "history": history, "profile": profile.to_dict(),
                "normaliser": normaliser.state_dict(), "seconds": seconds}, path)


def load_checkpoint(path: str | Path, keys: tuple[str, ...] = CHECKPOINT_KEYS) -> dict:
    """Read a checkpoint (or a saved model: ``keys`` :data:`MODEL_KEYS`) through the checks every saved
    file gets (:func:`~pgae_lite.util.storage.load_torch`: ``weights_only=True``, tensors and plain data only;
    the keys; finite weights, optimiser state and statistics) and its recipe's version
    (:func:`check_recipe_version`): the one reader of every model the book trains, the family's included.

    A folder in its place, an empty, truncated or foreign file, or NaN weights raise
    :class:`~pgae_lite.util.storage.CorruptCheckpointError`, another recipe version
    :class:`~pgae_lite.util.storage.CheckpointMismatchError`, each naming the file.
    """
    ckpt = load_torch(path, keys, finite=FINITE_KEYS)
    check_recipe_version(ckpt["profile"], path)
    return ckpt


def _same_numbers(a: list, b: list) -> bool:
    """Two (nested) lists of floats hold the same numbers, up to rounding."""
    a, b = (np.hstack([np.ravel(x) for x in v]).astype(float) for v in (a, b))
    return a.shape == b.shape and bool(np.allclose(a, b))


def check_trained_on(ckpt: dict, fitted: dict, path: str | Path, source: str = "") -> None:
    """Raise :class:`DataMismatchError` unless ``fitted`` (a normaliser's state, fitted on the
    training samples of the data at hand) equals the one saved in ``ckpt``."""
    saved = ckpt["normaliser"]
    differ = [k for k in saved if k not in fitted or not _same_numbers(fitted[k], saved[k])]
    if differ:
        raise DataMismatchError(
            f"{path} was not trained on this data ({source or 'dataset'}): the statistics of its training "
            f"samples ({', '.join(differ)}) differ from those saved with the model. Use the data it was "
            "trained on: for our simulated data the same cache (PGAE_LITE_CACHE), since the visual features "
            "come from the cache's CAE and a CAE trained elsewhere (or with another number of threads) gives "
            "other features; or train the model again on this data (another output folder).")


def check_recipe_version(recipe, path: str | Path) -> dict:
    """``recipe`` (a checkpoint's saved ``Profile.to_dict()``) if it was trained with this
    :data:`~pgae_lite.train.config.RECIPE_VERSION`;
    else a :class:`~pgae_lite.util.storage.CheckpointMismatchError` that says so."""
    version = recipe.get("recipe_version") if isinstance(recipe, dict) else None
    if version != RECIPE_VERSION:
        raise CheckpointMismatchError(
            f"{path} was trained with recipe version {version or 'before versions'}; this pgae_lite reads "
            f"version {RECIPE_VERSION} (an option's meaning or default changed since): train the model again")
    return recipe


def load_weights(model: nn.Module, ckpt: dict, path: str | Path) -> nn.Module:
    """``model`` with the checkpoint's weights (read by :func:`load_checkpoint`, which refuses NaN or infinite
    ones): refused with a one-sentence :class:`~pgae_lite.util.storage.CheckpointMismatchError` naming the
    tensors that are missing, foreign or of another shape (another model's weights, or altered)."""
    return load_state(model, ckpt["model"], path)


def check_fitted_on(ckpt: dict, dataset: PGAEDataset, path: str | Path, made_on: str = "") -> None:
    """Raise :class:`DataMismatchError` unless the checkpoint's model (or a sweep unit's result, which holds its
    recipe and normaliser too) was trained on ``dataset``: the normaliser fitted on its training samples (with the
    saved recipe's subset and scaling) equals the one saved. ``made_on``: where it was trained, for the message."""
    cfg = ckpt["profile"]["train"]
    fitted = Normaliser.fit(training_split(dataset, cfg.get("max_train_samples")),
                            cfg.get("vision_scaling", "global")).state_dict()
    check_trained_on(ckpt, fitted, path, dataset.source + (f"; the model was trained on {made_on}" if made_on else ""))


__all__ = ["CHECKPOINT", "CHECKPOINT_KEYS", "DataMismatchError", "FINITE_KEYS", "MODEL_KEYS",
           "check_fitted_on", "check_recipe_version",
           "check_trained_on", "load_checkpoint", "load_weights", "save_checkpoint", "training_split"]
