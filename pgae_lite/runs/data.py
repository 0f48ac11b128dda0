"""From nothing to a dataset the models learn from: simulator -> CAE -> visual features; where a run's data comes from.

Paper, Sec. 4 (dataset) and Sec. 3 (visual features from a channel-separated
CAE), on our simulated data. Each heavy step is cached, keyed by its config,
so every chapter can call :func:`simulated_dataset` and get in seconds what an
earlier chapter (or ``python -m pgae_lite simulate``) already made:

1. :func:`pgae_lite.sim.dataset.generate` records the episodes of the profile's
   world (the paper's, or one with a new colour: ``DatasetConfig.world``);
2. :func:`trained_cae` trains the CAE on frames of the training episodes only;
3. :func:`simulated_dataset` encodes every frame of both views into 30
   features and returns a :class:`~pgae_lite.data.dataset.PGAEDataset`.

A run's data is a value, :class:`AuthorsData` (the authors' folder) or :class:`SimulatedData` (a
profile's simulated data), that any process can load (:func:`loaded`, once per process): the runs
here, and a sweep's units on whichever worker they land (:mod:`pgae_lite.runs.table1_unit`).
Every function takes a :class:`~pgae_lite.config.Profile`, resolved once where the run starts.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, ClassVar

import numpy as np

from pgae_lite.cae import CAEConfig, ChannelSeparatedCAE, extract_features, load_cae, train_cae
from pgae_lite.config import Profile
from pgae_lite.data.dataset import DataFormatError, PGAEDataset
from pgae_lite.sim.dataset import DatasetConfig, episode_name, generate, to_dataset, training_frames
from pgae_lite.util.checks import shown
from pgae_lite.util.errors import ArgumentTypeError
from pgae_lite.util.storage import cache_dir, config_digest, make_folder

_LOADED: dict[tuple, PGAEDataset] = {}              # this process's data, loaded once per source


def cache_stem(data: DatasetConfig, cae: CAEConfig) -> str:
    """The cache name of the episodes of ``data`` seen through a CAE trained with ``cae``: two digests."""
    return f"{data.key()}-{config_digest(cae.to_dict())}"


def cae_path(data: DatasetConfig, cae: CAEConfig) -> Path:
    """Where the CAE trained on ``data`` with ``cae`` is cached."""
    return cache_dir() / "cae" / f"{cache_stem(data, cae)}.pt"


def profile_of(profile: Profile) -> Profile:
    """``profile`` if it is a Profile; else a one-sentence error (a name is resolved once, where a run starts)."""
    if not isinstance(profile, Profile):
        raise ArgumentTypeError(f"profile must be a Profile, resolved once where the run starts: "
                                f"pgae_lite.config.get_profile(name); got {shown(profile)}")
    return profile


def trained_cae(profile: Profile, device: str | None = None, progress: bool = True,
                workers: int | None = None) -> tuple[ChannelSeparatedCAE, list[dict]]:
    """The profile's CAE, trained on its simulated training episodes (cached) and its loss history."""
    data, cae = profile_of(profile).data, profile.cae
    generate(data, workers=workers, progress=progress)
    return cached_cae(cae_path(data, cae), cae,
                      lambda: training_frames(data, cae.frame_stride), device, progress)


def cached_cae(path: Path, cae: CAEConfig, frames: Callable[[], np.ndarray],
               device: str | None = None, progress: bool = True
               ) -> tuple[ChannelSeparatedCAE, list[dict]]:
    """The CAE cached at ``path``, else one trained with ``cae`` on ``frames()``."""
    if path.exists():  # the path is keyed by both configs: no need to read the frames again
        try:
            model, ckpt = load_cae(path, device)
            if ckpt["config"] == cae.to_dict():
                return model, ckpt["history"]
            raise ValueError(f"config {ckpt['config']} differs from {cae.to_dict()}")
        except Exception as e:  # a damaged or foreign file: train again rather than use it
            warnings.warn(f"{path}: cannot use this cached CAE ({e}); training it again", stacklevel=2)
            path.unlink()
    return train_cae(frames(), cae, device, progress, out_path=path)


def simulated_dataset(profile: Profile, device: str | None = None, progress: bool = True,
                      workers: int | None = None) -> PGAEDataset:
    """The profile's simulated dataset with CAE features: records, trains and encodes what is not cached."""
    prof = profile_of(profile)
    data, cae_config = prof.data, prof.cae
    path = cache_dir() / "features" / f"{cache_stem(data, cae_config)}.npz"

    def make() -> PGAEDataset:
        model, _ = trained_cae(prof, device, progress, workers)
        return to_dataset(data, lambda frames: extract_features(model, frames),
                          progress)
    return cached_dataset(path, make, {"data": data.to_dict(), "cae": cae_config.to_dict()},
                          f"simulated:{data.key()}", [f"sim/{episode_name(p, v)}" for p, v in data.episodes()])


def made_otherwise(dataset: PGAEDataset, source: str, ids: list[str]) -> str | None:
    """How ``dataset`` differs from the recordings ``ids`` of ``source`` it should hold, or None."""
    if dataset.source != source:
        return f"it holds data of {dataset.source!r}, not of {source!r}"
    if sorted(map(str, dataset.ids)) != sorted(ids):
        return f"it holds {len(dataset)} episodes, not the {len(ids)} recorded ones"
    return None


def cached_dataset(path: Path, make: Callable[[], PGAEDataset], configs: dict, source: str,
                   ids: list[str]) -> PGAEDataset:
    """The dataset cached at ``path``, else ``make()``'s, saved there.

    A cached file is used only if its fingerprint is the digest of ``configs`` (those that make
    the data, not the file's name), its arrays match their saved digest, and its content is what
    the configs make: data of ``source``, the episodes ``ids``. Else it is made again.
    """
    fingerprint = config_digest(configs)
    if path.exists():   # checked: the configs' fingerprint, the arrays' digest, finite, the content
        try:
            dataset = PGAEDataset.load(path, fingerprint=fingerprint)
            problem = made_otherwise(dataset, source, ids)
            if problem is None:
                return dataset
            warnings.warn(f"{path}: not this cache's data ({problem}); computing the features again",
                          stacklevel=2)
        except DataFormatError as e:
            warnings.warn(f"{e}; computing the features again", stacklevel=2)
    dataset = make()
    problem = made_otherwise(dataset, source, ids)
    if problem is not None:
        raise DataFormatError(f"the features made for {path} are not what the configs describe: {problem}")
    make_folder(path.parent)
    dataset.save(path, fingerprint=fingerprint)
    return dataset


# --------------------------------------------------------------------------- where a run's data comes from
@dataclass(frozen=True)
class AuthorsData:
    """A run's data: the authors' folder, read at the same path on every worker (a shared disk, or a copy)."""

    folder: str
    kind: ClassVar[str] = "original"

    def key(self) -> tuple:
        return ("original", self.folder)

    def load(self, device: str | None = None, progress: bool = False) -> PGAEDataset:
        from pgae_lite.data.original import load_original

        return load_original(self.folder)


@dataclass(frozen=True)
class SimulatedData:
    """A run's data: our simulated data of a profile's recordings and CAE, made in each worker's own cache if
    missing (:func:`simulated_dataset`)."""

    profile: Profile
    kind: ClassVar[str] = "simulated"

    def key(self) -> tuple:
        return ("simulated", str(cache_dir()), self.profile.data.key(), config_digest(self.profile.cae.to_dict()))

    def load(self, device: str | None = None, progress: bool = False) -> PGAEDataset:
        return simulated_dataset(self.profile, device, progress)


def data_source(original_data: str | Path | None, profile: Profile) -> AuthorsData | SimulatedData:
    """The authors' folder ``original_data`` (its absolute path), or, without one, ``profile``'s simulated data."""
    return SimulatedData(profile) if original_data is None else AuthorsData(str(Path(original_data).resolve()))


def loaded(source: AuthorsData | SimulatedData, device: str | None = None, progress: bool = False) -> PGAEDataset:
    """``source``'s data, loaded once per process: a chapter's trainings, or a sweep's worker for every unit it
    runs, read it once."""
    key = source.key()
    if key not in _LOADED:
        _LOADED[key] = source.load(device, progress)
    return _LOADED[key]


def remember(source: AuthorsData | SimulatedData, dataset: PGAEDataset) -> None:
    """Later :func:`loaded` calls of this process get ``dataset`` (loaded by the caller) for ``source``."""
    _LOADED[source.key()] = dataset


def worker_dataset(original_data: str | None, profile: Profile, device: str | None = None) -> PGAEDataset:
    """The data a unit trains and measures on, loaded once per process: the authors' folder
    ``original_data``, else ``profile``'s simulated data from this machine's cache (made if missing)."""
    return loaded(data_source(original_data, profile), device)


__all__ = ["AuthorsData", "SimulatedData", "cache_stem", "cae_path", "cached_cae", "cached_dataset", "data_source",
           "loaded", "made_otherwise", "profile_of", "remember", "simulated_dataset", "trained_cae", "worker_dataset"]
