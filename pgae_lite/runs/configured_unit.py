"""One unit of ``reproduce`` for a model configured per direction: PRAE, PVAE or PVAE-BERT(-tuned), one seed.

PGAE paper, Sec. 2 and 4 (PRAE, PVAE, their N.A. cells). The rows of
:data:`pgae_lite.config.CONFIGURED_ROWS` are trained by :func:`pgae_lite.family.train.train_family`
with the profile's recipe (under ``paper``, each model's authors', :func:`~pgae_lite.family.train.family_recipe`),
measured per configuration (:func:`pgae_lite.family.configured.evaluate_configured`), and return
what :func:`pgae_lite.runs.table1_unit.table1_unit` returns, N.A. cells as ``None``. The trained
model is saved to ``OUT/NAME-seedS/family.pt`` (atomically) and loaded from there by a later run
with the same recipe and data, so a finished training is never repeated.
"""
from __future__ import annotations

import platform
from dataclasses import replace
from pathlib import Path

from pgae_lite.config import Profile
from pgae_lite.data.dataset import Normaliser, PGAEDataset
from pgae_lite.family.configured import evaluate_configured
from pgae_lite.family.train import MODELS, TRAINING_VERSION, FamilyTrained, family_recipe, train_family
from pgae_lite.model.config import ModelConfig
from pgae_lite.train.checkpoint import check_trained_on, training_split
from pgae_lite.util.storage import CheckpointMismatchError, cache_dir, load_torch, save_torch

SAVED = "family.pt"


def configured_profile(profile: Profile, name: str, seed: int, samples: int | None = None) -> Profile:
    """The recipe of one configured unit: ``profile`` with the seed (and, given the training ``samples``,
    the model's own authors' training under the ``paper`` profile)."""
    train = replace(profile.train, seed=seed)
    if samples is not None:
        train = family_recipe(name, train, profile.name, samples)
    return replace(profile, train=train)


def _load(path: Path, name: str, prof: Profile, fitted: dict, source: str) -> FamilyTrained | None:
    """The model saved at ``path`` if it was trained with this recipe on this data; None if there is none."""
    if not path.exists():
        return None
    saved = load_torch(path, ("name", "model", "profile", "normaliser", "history", "seconds"), "family model")
    if saved["name"] != name or saved["profile"] != prof.to_dict():
        raise CheckpointMismatchError(f"{path} holds another model or recipe ({saved['name']}); use another "
                                      "output folder, or delete it to train again")
    if saved.get("training_version", 1) != TRAINING_VERSION:
        raise CheckpointMismatchError(f"{path} was trained by an older training code (version "
                                      f"{saved.get('training_version', 1)}, this one is {TRAINING_VERSION}); use "
                                      "another output folder, or delete it to train again")
    check_trained_on(saved, fitted, path, source)
    make, changes = MODELS[name]
    model = make(replace(ModelConfig(**saved["profile"]["model"]), **changes))
    model.load_state_dict(saved["model"])
    return FamilyTrained(model.eval(), Normaliser.from_state_dict(saved["normaliser"]), saved["history"],
                         saved["seconds"])


def trained_configured(path: Path, name: str, prof: Profile, dataset: PGAEDataset, device: str | None = None,
                       all_descriptions: bool | None = None) -> FamilyTrained:
    """``name`` trained with ``prof`` on ``dataset``: loaded from ``path`` if it was trained there with this
    recipe on this data, else trained and saved there (``all_descriptions``: see ``train_family``; a
    different value needs a different ``path``)."""
    train_set = training_split(dataset, prof.train.max_train_samples)       # what train_family fits on
    fitted = Normaliser.fit(train_set, prof.train.vision_scaling).state_dict()
    trained = _load(path, name, prof, fitted, dataset.source)
    if trained is None:
        trained = train_family(name, dataset, prof.model, prof.train, device, all_descriptions)
        save_torch({"name": name, "training_version": TRAINING_VERSION,
                    "model": trained.model.state_dict(), "profile": prof.to_dict(),
                    "normaliser": trained.normaliser.state_dict(), "history": trained.history,
                    "seconds": trained.seconds}, path)
    return trained


def configured_unit(dataset: PGAEDataset, profile: Profile, name: str, seed: int, out: str,
                    device: str | None = None) -> dict:
    """Train (or load) ``name`` with ``seed`` into ``out/NAME-seedS``, measure its configured cells."""
    prof = configured_profile(profile, name, seed, len(dataset.split("train")))
    trained = trained_configured(Path(out) / f"{name}-seed{seed}" / SAVED, name, prof, dataset, device)
    cells, predictions = evaluate_configured(trained.model, dataset, trained.normaliser)
    return {"training": name, "seed": seed, "seconds": trained.seconds, "cells": {name: cells},
            "profile": prof.to_dict(), "predictions": {name: predictions},
            "normaliser": trained.normaliser.state_dict(), "made_on": f"{platform.node()}, cache {cache_dir()}"}


__all__ = ["SAVED", "configured_profile", "configured_unit", "trained_configured"]
