"""The pipeline of a world with a new colour: record, retrain the CAE and PGAE.

Not from the paper: the book's guided project "Teach NICO a new colour"
(:mod:`pgae_lite.world.colours`). The same steps as :mod:`pgae_lite.runs.pipeline`, each
cached and keyed by its configs and by the world:

1. :func:`record` records the world's new patterns (the profile's variations,
   seed and simulator settings); the paper's 144 come from the profile's own
   cache, untouched;
2. :func:`trained_cae` trains a CAE on frames of the training episodes of both
   (the old CAE never saw the new colour);
3. :func:`extended_dataset` encodes every episode of both with it: one
   :class:`~pgae_lite.data.dataset.PGAEDataset` whose descriptions index the world's
   lexicon (the paper's words keep their indices);
4. :func:`trained_pgae` trains PGAE, built for the world's lexicon, on it.

:func:`load_pgae` reads such a model back (it needs the world: the checkpoint
holds the weights, the world says what the extra rows mean).
"""
from __future__ import annotations

from dataclasses import replace
from itertools import chain
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import torch

from pgae_lite.cae import ChannelSeparatedCAE, extract_features
from pgae_lite.config import Profile, get_profile
from pgae_lite.train.config import saved_model_config
from pgae_lite.data.dataset import PGAEDataset, from_recordings
from pgae_lite.model.pgae import PGAE
from pgae_lite.runs.pipeline import cached_cae, cached_dataset
from pgae_lite.data.simulated import (DatasetConfig, GenerationReport, episode_name, generate,
                      iter_episodes, training_frames)
from pgae_lite.util.storage import cache_dir, config_digest, default_device
from pgae_lite.world.colours import World

if TYPE_CHECKING:
    from pgae_lite.data.dataset import Normaliser
    from pgae_lite.train.loop import Trained


def new_recordings(world: World, profile: Profile | str | None = None) -> DatasetConfig:
    """What :func:`record` records: the world's new patterns, as the profile's data.

    ``profile`` here and below: a :class:`~pgae_lite.config.Profile`, or a name resolved once
    by the function called (``None``: the default profile).
    """
    if not world.new_patterns:
        raise ValueError("this world has no patterns beyond the paper's 144; extend it "
                         "first: world = with_colour(name, synonym, rgba)")
    return replace(get_profile(profile).data, patterns=world.new_patterns, world=world)


def record(world: World, profile: Profile | str | None = None, workers: int | None = None,
           progress: bool = True) -> GenerationReport:
    """Record the world's new episodes (cached: only what is missing is recorded)."""
    return generate(new_recordings(world, profile), workers=workers, progress=progress)


def _stem(world: World, prof: Profile) -> str:
    """Cache name: the old data's key, the new data's key, the CAE's config digest."""
    new = new_recordings(world, prof)
    return f"{prof.data.key()}+{new.key()}-{config_digest(prof.cae.to_dict())}"


def cae_path(world: World, profile: Profile | str | None = None) -> Path:
    """Where the CAE of the old and the new recordings is cached."""
    return cache_dir() / "cae" / f"{_stem(world, get_profile(profile))}.pt"


def trained_cae(world: World, profile: Profile | str | None = None, device: str | None = None,
                progress: bool = True, workers: int | None = None
                ) -> tuple[ChannelSeparatedCAE, list[dict]]:
    """A CAE (the profile's recipe) trained on old and new training episodes' frames."""
    prof = get_profile(profile)
    old, new = prof.data, new_recordings(world, prof)
    generate(old, workers=workers, progress=progress)
    generate(new, workers=workers, progress=progress)
    stride = prof.cae.frame_stride

    def frames() -> np.ndarray:                                  # (N, 120, 160, 3)
        return np.concatenate([training_frames(old, stride),
                               training_frames(new, stride)])
    return cached_cae(cae_path(world, prof), prof.cae, frames, device, progress)


def extended_dataset(world: World, profile: Profile | str | None = None,
                     device: str | None = None, progress: bool = True,
                     workers: int | None = None) -> PGAEDataset:
    """Old and new episodes, the new CAE's features (cached), in the world's words."""
    prof = get_profile(profile)
    new = new_recordings(world, prof)

    def make() -> PGAEDataset:
        model, _ = trained_cae(world, prof, device, progress, workers)

        def features(frames: np.ndarray) -> np.ndarray:    # (T, 120, 160, 3) -> (T, 30)
            return extract_features(model, frames)
        episodes = chain(iter_episodes(prof.data), iter_episodes(new))
        return from_recordings(
            ((world.pattern(ep.pattern),
              f"sim/{episode_name(ep.pattern, ep.variation)}",
              ep.joints, features(ep.images), features(ep.images_opposite))
             for ep in episodes), source=f"simulated:{prof.data.key()}+{new.key()}")
    path = cache_dir() / "features" / f"{_stem(world, prof)}.npz"
    ids = [f"sim/{episode_name(p, v)}" for config in (prof.data, new) for p, v in config.episodes()]
    return cached_dataset(path, make, {"data": prof.data.to_dict(), "new": new.to_dict(), "cae": prof.cae.to_dict()},
                          f"simulated:{prof.data.key()}+{new.key()}", ids)


def pgae_folder(world: World, profile: Profile | str | None = None, seed: int = 0,
                **train_overrides) -> Path:
    """Where :func:`trained_pgae` keeps its checkpoint (the recipe's digest holds its version)."""
    prof = get_profile(profile, seed=seed, **train_overrides)
    recipe = config_digest(prof.to_dict())
    return cache_dir() / "pgae" / f"{_stem(world, prof)}-PGAE-{recipe}"


def trained_pgae(world: World, profile: Profile | str | None = None, seed: int = 0,
                 device: str | None = None, progress: bool = True,
                 **train_overrides) -> Trained:
    """PGAE built for the world's lexicon, trained (the profile's recipe) on
    :func:`extended_dataset`; cached, and resumed after an interruption."""
    from pgae_lite.train.loop import train

    prof = get_profile(profile, seed=seed, **train_overrides)     # a name is resolved once, here
    if prof.model.language_encoder != "lstm":
        raise ValueError("a new colour needs PGAE's own language encoder "
                         "(language_encoder='lstm'); PGAE-BERT reads the paper's words")
    dataset = extended_dataset(world, prof, device, progress)
    torch.manual_seed(prof.train.seed)      # the same initialisation every run
    model = PGAE(prof.model, world.lexicon)
    folder = pgae_folder(world, prof)
    return train(dataset, prof, out_dir=folder, device=device, progress=progress,
                 model=model)


def load_pgae(path: str | Path, world: World, device: str | None = None
              ) -> tuple[PGAE, Normaliser, dict]:
    """Model (eval mode), normaliser and checkpoint of a PGAE trained for ``world``."""
    from pgae_lite.data.dataset import Normaliser
    from pgae_lite.train.checkpoint import CHECKPOINT, load_checkpoint

    path = Path(path)
    ckpt = load_checkpoint(path / CHECKPOINT if path.is_dir() else path)
    model = PGAE(saved_model_config(ckpt["profile"], path), world.lexicon)
    try:
        model.load_state_dict(ckpt["model"])
    except RuntimeError as e:                     # the first mismatch, e.g. the words
        first = next((line.strip() for line in str(e).splitlines()[1:]), str(e))
        raise ValueError(f"{path} does not fit PGAE for this world's "
                         f"{world.lexicon.size} words: {first}") from None
    model.to(device or default_device()).eval()
    return model, Normaliser.from_state_dict(ckpt["normaliser"]), ckpt


__all__ = ["new_recordings", "record", "trained_cae", "cae_path", "extended_dataset",
           "trained_pgae", "pgae_folder", "load_pgae"]
