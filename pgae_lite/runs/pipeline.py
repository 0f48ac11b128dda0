"""From a profile's data to its trained models, each cached: any model of the book (paper Sec. 4).

On the profile's simulated data (:mod:`pgae_lite.runs.data`: simulator -> CAE -> visual features,
each step cached), :func:`trained_model` trains one training of :mod:`pgae_lite.runs.rows` (a row's
model of Table 1 or of the family, or a side training) by the one training loop, cached under the
digests of its data and its recipe, so every chapter gets in seconds what an earlier chapter
already trained; :func:`trained_models` trains several at the same time, sharing the CPU's cores;
:func:`load_model` reads a saved model back. Every function takes a
:class:`~pgae_lite.config.Profile`, resolved once where the run starts.
"""
from __future__ import annotations

import os
import time
import warnings
from dataclasses import fields, replace
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING

from pgae_lite.bert.config import PretrainedConfig
from pgae_lite.config import Profile
from pgae_lite.data.dataset import PGAEDataset
from pgae_lite.data.normaliser import Normaliser
from pgae_lite.freeform.attention_pooling import AttentionConfig
from pgae_lite.freeform.phrasing_bank import PhrasingsConfig, for_training
from pgae_lite.model.build import build_model
from pgae_lite.model.config import PARTS, ModelConfig
from pgae_lite.model.prae import BindingConfig
from pgae_lite.model.ptae import CrossmodalConfig
from pgae_lite.runs.data import SimulatedData, cache_stem, loaded, profile_of
from pgae_lite.runs.rows import Training
from pgae_lite.runs.sweep import run_sweep
from pgae_lite.train.config import TRAIN_PARTS, TrainConfig
from pgae_lite.train.supervision import SupervisionConfig
from pgae_lite.util.checks import instance_of
from pgae_lite.util.storage import (
    CheckpointMismatchError,
    CorruptCheckpointError,
    FolderBusyError,
    OutputError,
    cache_dir,
    config_digest,
    config_from,
    default_device,
)

if TYPE_CHECKING:
    import torch

    from pgae_lite.train.loop import Trained

#: Every part a recipe may hold, by the kind its dict names (recipe_from_dict).
PART_KINDS = {c.kind: c for c in (PretrainedConfig, AttentionConfig, CrossmodalConfig, BindingConfig,
                                  SupervisionConfig, PhrasingsConfig)}
BUSY_POLL_SECONDS = 5      # how often trained_model looks whether another process's training has ended


def model_folder(prof: Profile, training: str) -> Path:
    """Where the model of ``training`` with the recipe ``prof`` is cached: the data's and the recipe's digests
    (the recipe's holds its version and, for a training on phrasings, which sentences it reads)."""
    return cache_dir() / "pgae" / f"{cache_stem(prof.data, prof.cae)}-{training}-{config_digest(prof.to_dict())}"


def language_source(prof: Profile):
    """What the training loop reads each batch's language features from, for ``prof``'s recipe: None, or for
    a training on phrasings the free-form variant's bank (:func:`pgae_lite.freeform.phrasing_bank.for_training`)."""
    phrasings = prof.train.phrasings
    return None if phrasings is None else partial(for_training, config=phrasings, seed=prof.train.seed)


def unit_profile(profile: Profile, training: Training, seed: int, dataset: PGAEDataset,
                 pretrained_model: str | None = None) -> Profile:
    """The recipe of one training with ``seed`` on ``dataset`` (its size: for a training whose authors counted
    iterations, under the paper profile)."""
    base = replace(profile, train=replace(profile.train, seed=seed))
    return training.profile(base, len(dataset.split("train")), pretrained_model)


def trained_model(training: Training, profile: Profile, seed: int = 0, device: str | None = None,
                  progress: bool = True) -> "Trained":
    """The model of one training (:mod:`pgae_lite.runs.rows`: a row's of Table 1 or of the family, or a side
    training) on the profile's simulated data, cached: loaded if it was trained before.

    An interrupted training resumes from its last checkpoint. When another process is training the same
    model into the cache (two chapters run side by side), this waits for it and then loads its model.
    """
    from pgae_lite.train.checkpoint import CHECKPOINT, DataMismatchError

    instance_of("training", training, Training, "a Training of pgae_lite.runs.rows (e.g. TRAININGS['PGAE'])")
    dataset = _with_both_splits(loaded(SimulatedData(profile_of(profile)), device, progress))
    prof = unit_profile(profile, training, seed, dataset)
    folder = model_folder(prof, training.name)
    while True:
        try:
            return train_when_free(dataset, prof, folder, device, progress, training.name, announce=progress)
        # Damaged, or saved with other data statistics (the folder's name fixes the data and CAE, so an
        # older pgae_lite scaled them otherwise): trained again, like the CAE.
        except (CorruptCheckpointError, DataMismatchError) as e:
            if not (folder / CHECKPOINT).is_file():      # a folder in its place: not ours to delete
                raise
            warnings.warn(f"cached model not used, training it again: {e}", stacklevel=2)
            try:
                (folder / CHECKPOINT).unlink()
            except OSError as gone:                     # a read-only cache: said, with what was wrong
                raise OutputError(f"{e}; it cannot be trained again there: {gone.strerror or gone}") from None


def train_when_free(dataset: PGAEDataset, prof: Profile, folder: Path, device: str | None, progress: bool,
                    name: str, announce: bool = True) -> "Trained":
    """``train`` into ``folder``; while another process trains this very model there (two chapters, or
    two sweeps, side by side), wait for it (said once, if ``announce``) and then load what it trained."""
    from pgae_lite.train.loop import train

    announced = False
    while True:
        try:
            return train(dataset, prof, out_dir=folder, device=device, progress=progress, name=name,
                         language=language_source(prof))
        except FolderBusyError:
            if announce and not announced:
                print(f"{name}: another process is training this model; waiting for it ...", flush=True)
            announced = True
            time.sleep(BUSY_POLL_SECONDS)


def _with_both_splits(dataset: PGAEDataset) -> PGAEDataset:
    """``dataset``, or a DataFormatError before any training if it lacks training or test samples: Table 1's
    models are trained on the one and measured on the other."""
    dataset.split("train"), dataset.split("test")
    return dataset


def _train_alone(training: Training, profile: Profile, seed: int) -> float:
    """A worker of :func:`trained_models`: one training on one thread; its training time (s)."""
    import torch

    torch.set_num_threads(1)
    return trained_model(training, profile, seed, device="cpu", progress=False).seconds


def trained_models(trainings: list[Training], profile: Profile, seed: int = 0, device: str | None = None,
                   progress: bool = True, workers: int | None = None) -> dict[str, "Trained"]:
    """Several of :func:`trained_model`'s models, by training name; those not cached are trained side by side.

    On a CPU the missing models train at the same time, each a unit of a sweep
    (:func:`pgae_lite.runs.sweep.run_sweep`) on a worker process of one thread, ``workers``
    at once (default: all of them, up to two per core). These networks are small: on the
    book's 2-core machine one training on both cores ran no faster than on one (A2, "Where
    the time goes"), so two trainings side by side take about the time of one. Three
    trainings of about equal length on two cores share the cores and end together, after
    about one and a half trainings' time, where two at a time would take two. A worker has
    one thread, so its model's numbers do not depend on how many run at once. With a GPU,
    or one model to train, they train one after another in this process, as
    :func:`trained_model` does. Workers are spawned, so a script that calls this needs the
    usual ``if __name__ == "__main__":`` guard.
    """
    import torch

    prof = profile_of(profile)
    for training in trainings:
        instance_of("training", training, Training, "a Training of pgae_lite.runs.rows (e.g. TRAININGS['PGAE'])")
    cpu = torch.device(device or default_device()).type == "cpu"
    dataset = _with_both_splits(loaded(SimulatedData(prof), device, progress))   # made before the workers read it
    todo = [t for t in {t.name: t for t in trainings}.values() if not is_trained(t, prof, seed, dataset)]
    cores = os.cpu_count() or 1
    workers = max(1, min(workers or 2 * cores, len(todo)))     # more than cores: they share them
    if cpu and workers > 1:
        if progress:
            names = ", ".join(t.name for t in todo)
            print(f"training {names} side by side, {workers} at a time on {cores} cores, "
                  "one thread each ...", flush=True)
        seconds = run_sweep(_train_alone, [(t, prof, seed) for t in todo], workers=workers, name="training",
                            progress=False)
        for training, s in zip(todo, seconds):
            if progress:
                print(f"{training.name}: trained in {s / 60:.1f} min", flush=True)
    return {t.name: trained_model(t, prof, seed, device, progress) for t in trainings}


def is_trained(training: Training, profile: Profile, seed: int, dataset: PGAEDataset) -> bool:
    """Whether :func:`trained_model` would load this model from the cache, trained to its last epoch."""
    from pgae_lite.train.checkpoint import CHECKPOINT, load_checkpoint

    prof = unit_profile(profile, training, seed, dataset)
    try:
        return load_checkpoint(model_folder(prof, training.name) / CHECKPOINT)["epoch"] >= prof.train.epochs
    except Exception:  # noqa: BLE001 -- missing or damaged: trained_model trains (again)
        return False


def _with_parts(settings, parts: tuple[str, ...], where: str, path: str | Path) -> dict:
    """A saved config's dict with each part's dict made its part again (by its kind)."""
    if not isinstance(settings, dict):
        raise CheckpointMismatchError(f"{path} holds no {where} (a {type(settings).__name__}, not a dict of "
                                      "settings): it is not a pgae_lite checkpoint, or it was altered")
    out = dict(settings)
    for name in parts:
        if out.get(name) is not None:
            kind = out[name].get("kind") if isinstance(out[name], dict) else None
            if kind not in PART_KINDS:
                raise CheckpointMismatchError(f"{path}, {where}: unknown part {name}={kind!r}; the parts are: "
                                              f"{', '.join(PART_KINDS)}")
            settings = {f.name for f in fields(PART_KINDS[kind])}       # not what its dict adds (kind, digests)
            out[name] = config_from(PART_KINDS[kind], {k: v for k, v in out[name].items() if k in settings},
                                    path, f"the {name} part of {where}")
    return out


def recipe_from_dict(recipe: dict, path: str | Path = "the recipe") -> tuple[ModelConfig, TrainConfig]:
    """The model's and the training's settings of a recipe saved as :meth:`~pgae_lite.config.Profile.to_dict`
    wrote it (a checkpoint's, read from ``path``): a setting this version does not know, or refuses, is a
    :class:`~pgae_lite.util.storage.CheckpointMismatchError` that names it."""
    if not isinstance(recipe, dict) or not {"model", "train"} <= set(recipe):
        raise CheckpointMismatchError(f"{path} holds no recipe (the model's and the training's settings): it is "
                                      "not a pgae_lite checkpoint, or it was altered")
    model = config_from(ModelConfig, _with_parts(recipe["model"], PARTS, "the model's settings", path), path,
                        "the model's settings")
    train = config_from(TrainConfig, _with_parts(recipe["train"], TRAIN_PARTS, "the training's settings", path),
                        path, "the training's settings")
    return model, train


def load_model(path: str | Path, device: "torch.device | str | None" = None, dataset: PGAEDataset | None = None,
               lexicon=None) -> tuple["torch.nn.Module", Normaliser, dict]:
    """Model (in eval mode), normaliser and the checkpoint's other contents, from a checkpoint any training of
    the book wrote (``lexicon``: a model of a larger vocabulary, e.g. a world with a new colour).

    With ``dataset``, first check that the model was trained on it: the normaliser fitted on its training
    samples must equal the one saved. The visual features come from a CAE, and two CAEs (e.g. trained with
    another number of threads, in another cache) give different features: a model fed another CAE's
    features produces nonsense without any error, so this raises a DataMismatchError instead.
    """
    from pgae_lite.train.checkpoint import MODEL_KEYS, check_fitted_on, load_checkpoint, load_weights
    from pgae_lite.world.words import DEFAULT_LEXICON

    ckpt = load_checkpoint(path, MODEL_KEYS)            # the checks every saved file gets, and the recipe's version
    if dataset is not None:
        check_fitted_on(ckpt, dataset, path)
    model_cfg, recipe = recipe_from_dict(ckpt["profile"], path)
    model = load_weights(build_model(model_cfg, lexicon or DEFAULT_LEXICON), ckpt, path)
    model.at_step(recipe.epochs, recipe.epochs)                       # its training is over
    model.to(device or default_device()).eval()
    return model, Normaliser.from_state_dict(ckpt["normaliser"]), ckpt


__all__ = ["PART_KINDS", "is_trained", "language_source", "load_model", "model_folder", "recipe_from_dict",
           "train_when_free", "trained_model", "trained_models", "unit_profile"]
