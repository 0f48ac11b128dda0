"""The simulated dataset: every pattern recorded in our simulator, cached on disk.

Paper, Sec. 4 (Dataset), with our pybullet world (:mod:`pgae_lite.sim`) in
place of the authors' Blender scenes: the same 144 patterns (12 cube
arrangements x 12 actions) x 6 variations = 864 episodes, the same 36 test
patterns, joints padded to 100 steps, 120x160 images of NICO's own view and of
the opposite agent's.

Recording takes minutes, so episodes go through a cache keyed by the
generation config:

    {cache}/episodes/{key}/config.json         what was asked for
    {cache}/episodes/{key}/PPP-V.npz           one episode (joints, both views, ...)
    {cache}/episodes/{key}/manifest.json       episode -> seed, attempts, file digest

Each file is written atomically (a temporary file, then a rename), so an
interrupted run leaves only whole files; the next run records only what is
missing. A file whose digest does not match the manifest (or, if it is not in
the manifest yet, whose contents fail their own check, or hold another
episode than its name says) is reported and recorded again, never used.

:func:`~pgae_lite.runs.data.simulated_dataset` turns the episodes into the same
:class:`~pgae_lite.data.dataset.PGAEDataset` as the authors' loader produces, with
visual features from a trained channel-separated CAE (also cached).
"""
from __future__ import annotations

import hashlib
import json
import os
import time
import warnings
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict, dataclass, field, replace
from multiprocessing import current_process, get_context
from pathlib import Path
from typing import Callable, Iterator

import numpy as np
from tqdm.auto import tqdm

from pgae_lite.data.dataset import PGAEDataset, from_recordings
from pgae_lite.sim.record import Episode, SimConfig, record_episode
from pgae_lite.util.errors import PGAELiteError
from pgae_lite.util.storage import array_digest, atomic_write, atomic_write_text, cache_dir, config_digest, make_folder
from pgae_lite.world.colours import DEFAULT_WORLD, PAPER_PATTERNS, World

#: Bump when the simulator changes what it records: old caches are then not reused.
GENERATOR_VERSION = 4
IMAGE_SHAPE = (120, 160, 3)
MIN_JOBS_PER_WORKER = 24      # below this many episodes per process, one process is faster


@dataclass(frozen=True)
class DatasetConfig:
    """What to record: which patterns, how many variations of each, from which seed.

    ``world``: a world with more colours and patterns
    (:func:`pgae_lite.world.colours.with_colour`); None is the paper's, and leaves the cache
    key as it always was.
    """

    variations: int = 6
    patterns: tuple[int, ...] | None = None   # None: all 144 (all of the world's)
    base_seed: int = 0
    sim: SimConfig = field(default_factory=SimConfig)
    world: World | None = None

    @property
    def the_world(self) -> World:
        return self.world or DEFAULT_WORLD

    def pattern_list(self) -> list[int]:
        if self.patterns is None:
            return list(range(self.the_world.n_patterns))
        return sorted(self.patterns)

    def to_dict(self) -> dict:
        """Plain values; ``world`` only when given (the paper's key stays the same)."""
        d = asdict(replace(self, world=None))
        d.pop("world")
        if self.world is not None:
            d["world"] = self.world.to_dict()
        return d

    def episodes(self) -> list[tuple[int, int]]:
        """(pattern, variation) of every episode, in a fixed order."""
        return [(p, v) for p in self.pattern_list() for v in range(self.variations)]

    def key(self) -> str:
        """Short digest of the config (and the generator version): the cache folder's name."""
        return config_digest({"version": GENERATOR_VERSION, **self.to_dict()})

    def parts(self) -> list["DatasetConfig"]:
        """The recordings this dataset is made of, each in a cache folder of its own: with a world beyond the
        paper's, its patterns that the paper's world has are the paper's recordings (the same episodes, the
        paper's folder untouched), the rest the world's own; else the dataset itself."""
        patterns = self.pattern_list()
        paper = [p for p in patterns if p < PAPER_PATTERNS]
        new = tuple(p for p in patterns if p >= PAPER_PATTERNS)
        if self.world is None or not paper:
            return [self]
        own = replace(self, world=None, patterns=None if paper == list(range(PAPER_PATTERNS)) else tuple(paper))
        return [own] + ([replace(self, patterns=new)] if new else [])


class CorruptEpisodeError(PGAELiteError, RuntimeError):
    """A cached episode file is damaged or does not match what was recorded."""


# --------------------------------------------------------------------------- one file per episode
def episode_name(pattern: int, variation: int) -> str:
    return f"{pattern:03d}-{variation}"


def file_digest(path: Path) -> str:
    """Digest of a file's bytes (the manifest's check)."""
    h = hashlib.blake2b(digest_size=16)
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def _to_differences(frames: np.ndarray) -> np.ndarray:
    """Frame 0, then frame t minus frame t-1 (uint8, wrapping): mostly zeros, so it compresses 2-3x better."""
    return np.diff(frames, axis=0, prepend=np.zeros_like(frames[:1]))


def _from_differences(diffs: np.ndarray) -> np.ndarray:
    return np.cumsum(diffs, axis=0, dtype=np.uint8)             # sums wrap modulo 256: exact inverse


def save_episode(path: Path, ep: Episode) -> None:
    """Write one episode atomically, with a digest of its contents inside."""
    arrays = {"joints": ep.joints, "images": ep.images, "images_opposite": ep.images_opposite,
              "displacement": ep.displacement,
              "meta": np.array([ep.pattern, ep.variation, ep.seed, ep.attempts], dtype=np.int64)}
    digest = array_digest(arrays)
    for view in ("images", "images_opposite"):
        arrays[view] = _to_differences(arrays[view])
    with atomic_write(path) as f:
        np.savez_compressed(f, digest=np.array(digest), **arrays)


def load_episode_file(path: Path, world: World | None = None) -> Episode:
    """Read and check one episode file; :class:`CorruptEpisodeError` if it is damaged.

    ``world``: the world whose patterns it may hold (default: the paper's).
    """
    try:
        with np.load(path, allow_pickle=False) as f:
            arrays = {k: f[k] for k in ("joints", "images", "images_opposite", "displacement", "meta")}
            digest = str(f["digest"])
        for view in ("images", "images_opposite"):
            arrays[view] = _from_differences(arrays[view])
    except Exception as e:  # zip, zlib or format errors: all mean the same thing here
        raise CorruptEpisodeError(f"{path}: unreadable ({type(e).__name__}: {e})") from None
    if array_digest(arrays) != digest:
        raise CorruptEpisodeError(f"{path}: contents do not match their digest")
    pattern, variation, seed, attempts = (int(x) for x in arrays["meta"])
    steps = (world or DEFAULT_WORLD).pattern(pattern).steps
    if (arrays["joints"].shape != (steps, 5) or arrays["images"].shape != (steps, *IMAGE_SHAPE)
            or arrays["images_opposite"].shape != (steps, *IMAGE_SHAPE)):
        raise CorruptEpisodeError(f"{path}: unexpected shapes {arrays['joints'].shape}, {arrays['images'].shape}")
    if path.stem != episode_name(pattern, variation):   # e.g. copied over another
        raise CorruptEpisodeError(f"{path}: holds episode "
                                  f"{episode_name(pattern, variation)}, not the one "
                                  "its name says")
    return Episode(pattern=pattern, variation=variation, seed=seed, attempts=attempts,
                   joints=arrays["joints"], images=arrays["images"],
                   images_opposite=arrays["images_opposite"], displacement=arrays["displacement"], valid=True)


def _record_and_save(args: tuple[int, int, SimConfig, int, str, World]) -> dict:
    """Worker: record one episode, save it, return its manifest entry."""
    pattern, variation, sim_config, base_seed, folder, world = args
    t0 = time.perf_counter()
    ep = record_episode(pattern, variation, sim_config, base_seed, world)
    path = Path(folder) / f"{episode_name(pattern, variation)}.npz"
    save_episode(path, ep)
    return {"name": episode_name(pattern, variation), "seed": ep.seed, "attempts": ep.attempts,
            "steps": len(ep.joints), "digest": file_digest(path), "seconds": time.perf_counter() - t0}


# --------------------------------------------------------------------------- the whole set
@dataclass
class GenerationReport:
    """What :func:`generate` did."""

    folder: Path
    episodes: int              # episodes in the dataset
    recorded: int              # recorded in this call (the rest came from the cache)
    corrupt: int               # damaged files found and recorded again
    first_try: float           # fraction of all episodes valid on their first seed
    seconds: float             # wall time of this call
    megabytes: float           # size of the episode files on disk


def episode_folder(config: DatasetConfig) -> Path:
    return cache_dir() / "episodes" / config.key()


def _read_manifest(folder: Path) -> dict[str, dict]:
    try:
        return json.loads((folder / "manifest.json").read_text())
    except (OSError, ValueError):
        return {}


def _write_json(path: Path, obj) -> None:
    atomic_write_text(path, json.dumps(obj, indent=1, sort_keys=True))


def generate(config: DatasetConfig | None = None, workers: int | None = None,
             progress: bool = True) -> GenerationReport:
    """Record every episode of ``config`` that the cache does not hold yet.

    ``workers`` processes record in parallel (default: one per CPU core, or one
    process for a few dozen episodes, where starting workers costs more); they are
    spawned, so a script that calls this needs the usual ``if __name__ == "__main__":`` guard.
    Safe to interrupt and to call again; damaged files are recorded again.
    """
    config = config or DatasetConfig()          # the book's (its profiles: pgae_lite.config)
    if len(config.parts()) > 1:                 # the paper's recordings, then a new world's own
        reports = [generate(part, workers, progress) for part in config.parts()]
        episodes = sum(r.episodes for r in reports)
        first_try = sum(r.first_try * r.episodes for r in reports) / episodes
        return GenerationReport(reports[-1].folder, episodes, sum(r.recorded for r in reports),
                                sum(r.corrupt for r in reports), first_try, sum(r.seconds for r in reports),
                                sum(r.megabytes for r in reports))
    t0 = time.perf_counter()
    folder = episode_folder(config)
    make_folder(folder)
    _write_json(folder / "config.json",
                {"version": GENERATOR_VERSION, **config.to_dict()})
    manifest = _read_manifest(folder)
    todo, corrupt = [], 0
    for p, v in config.episodes():
        name = episode_name(p, v)
        path = folder / f"{name}.npz"
        if not path.exists():
            todo.append((p, v))
            continue
        entry = manifest.get(name)
        if entry is not None and file_digest(path) == entry["digest"]:
            continue
        try:                      # a whole file that never reached the manifest, or a damaged one
            ep = load_episode_file(path, config.world)
            if entry is not None:
                raise CorruptEpisodeError(f"{path}: file digest differs from the manifest")
            manifest[name] = {"name": name, "seed": ep.seed, "attempts": ep.attempts,
                              "steps": len(ep.joints), "digest": file_digest(path), "seconds": 0.0}
        except CorruptEpisodeError as e:
            warnings.warn(f"{e}; recording it again", stacklevel=2)
            corrupt += 1
            manifest.pop(name, None)
            todo.append((p, v))
    jobs = [(p, v, config.sim, config.base_seed, str(folder), config.the_world)
            for p, v in todo]
    if workers is None:   # a new worker process takes seconds to start (it imports torch): not worth it for few jobs
        workers = (os.cpu_count() or 1) if len(jobs) >= 2 * MIN_JOBS_PER_WORKER else 1
    workers = max(1, min(workers, len(jobs)))
    bar = tqdm(total=len(jobs), desc="recording episodes", disable=not progress or not jobs, unit="ep")
    last_save = time.perf_counter()
    for entry in _run(jobs, workers):
        manifest[entry["name"]] = entry
        bar.update()
        if time.perf_counter() - last_save > 5:      # keep the manifest current if interrupted
            _write_json(folder / "manifest.json", manifest)
            last_save = time.perf_counter()
    bar.close()
    _write_json(folder / "manifest.json", manifest)
    names = [episode_name(p, v) for p, v in config.episodes()]
    first = np.mean([manifest[n]["attempts"] == 1 for n in names])
    size = sum((folder / f"{n}.npz").stat().st_size for n in names) / 1e6
    return GenerationReport(folder, len(names), len(jobs), corrupt, float(first),
                            time.perf_counter() - t0, size)


def _run(jobs: list, workers: int) -> Iterator[dict]:
    # A daemon process (a Dask worker's: a sweep's unit on a machine without the data) may not start others.
    if workers == 1 or current_process().daemon:
        yield from map(_record_and_save, jobs)
        return
    # "spawn": fresh interpreters, safe beside torch threads and inside notebooks.
    with ProcessPoolExecutor(workers, mp_context=get_context("spawn")) as pool:
        yield from pool.map(_record_and_save, jobs, chunksize=1)


def load_episode(config: DatasetConfig, pattern: int, variation: int = 0) -> Episode:
    """One recorded episode (recording the whole dataset first if the cache lacks it)."""
    if (pattern, variation) not in set(config.episodes()):
        raise ValueError(f"episode (pattern {pattern}, variation {variation}) is not in this dataset: "
                         f"patterns {config.pattern_list()[0]}..{config.pattern_list()[-1]}, "
                         f"variations 0..{config.variations - 1}")
    part = next(c for c in config.parts() if pattern in c.pattern_list())
    path = episode_folder(part) / f"{episode_name(pattern, variation)}.npz"
    if not path.exists():
        generate(part)
    return load_episode_file(path, part.world)


def iter_episodes(config: DatasetConfig, split: str | None = None) -> Iterator[Episode]:
    """Every episode of the dataset in order (``split``: ``"train"``, ``"test"`` or all)."""
    generate(config, progress=False)
    for part in config.parts():
        for p, v in part.episodes():
            if split is None or part.the_world.pattern(p).is_test == (split == "test"):
                path = episode_folder(part) / f"{episode_name(p, v)}.npz"
                yield load_episode_file(path, part.world)


def training_frames(config: DatasetConfig, stride: int = 4, views: tuple[str, ...] = ("images", "images_opposite")
                    ) -> np.ndarray:
    """Every ``stride``-th frame of the training episodes, both views: CAE training images (N, 120, 160, 3)."""
    frames = [getattr(ep, view)[::stride] for ep in iter_episodes(config, "train") for view in views]
    return np.concatenate(frames)


def to_dataset(config: DatasetConfig, features: Callable[[np.ndarray], np.ndarray],
               progress: bool = True) -> PGAEDataset:
    """The episodes as a :class:`~pgae_lite.data.dataset.PGAEDataset`.

    ``features`` maps an episode's frames (T, 120, 160, 3) to its visual features (T, 30).
    """
    episodes = tqdm(iter_episodes(config), total=len(config.episodes()), desc="visual features",
                    unit="ep", disable=not progress)
    world = config.the_world
    return from_recordings(((world.pattern(ep.pattern),
                             f"sim/{episode_name(ep.pattern, ep.variation)}",
                             ep.joints, features(ep.images), features(ep.images_opposite)) for ep in episodes),
                           source=f"simulated:{config.key()}")


__all__ = ["DatasetConfig", "GenerationReport", "CorruptEpisodeError",
           "generate", "load_episode", "iter_episodes", "training_frames", "to_dataset",
           "episode_folder", "save_episode", "load_episode_file"]
