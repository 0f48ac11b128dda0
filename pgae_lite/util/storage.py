"""Shared plumbing: the cache folder, the device, config digests, saved torch files (no paper section).

What several modules need and none of them owns. It imports nothing from
``pgae_lite`` but the other utilities, so any module may import it without a cycle.

- :func:`cache_dir`: the root of every cache (``$PGAE_LITE_CACHE``);
- :func:`default_device`: CUDA when present, else the CPU;
- :func:`training_threads`: a training on the CPU runs on a fixed number of torch
  threads, so that a seed gives the same model on any machine;
- :func:`config_digest`: the short digest of a config that names its cache entry;
  :func:`array_digest`: a digest of arrays' contents (a cache file's check);
- :func:`save_torch`, :func:`load_torch`: every saved file (a model, the CAE, a checkpoint, a cache) written
  atomically and read with ``weights_only=True`` through one set of checks (a folder in the way, a damaged or
  unsafe file, missing keys, NaN or infinite weights), each failure one sentence naming the file;
  :func:`load_state`: saved weights into a model, the missing or foreign tensors named;
  :func:`config_from`: a saved config made a config again, an unknown setting named;
- :class:`CheckpointMismatchError`: a file holds the work of another recipe.

Atomic writes (:mod:`pgae_lite.util.atomic_files`) and the folder lock (:mod:`pgae_lite.util.folder_lock`)
live in their own modules; their names are importable from here too.
"""
from __future__ import annotations

import contextlib
import dataclasses
import hashlib
import json
import math
import os
import pickle
from pathlib import Path
from typing import Iterator

import numpy as np
import torch

from pgae_lite.util.atomic_files import (  # noqa: F401 -- importable from here, as the package always did
    OutputError,
    atomic_folder,
    atomic_path,
    atomic_write,
    atomic_write_text,
    dangling_link,
    make_folder,
    why_failed,
)
from pgae_lite.util.errors import PGAELiteError
from pgae_lite.util.folder_lock import (  # noqa: F401 -- importable from here, as the package always did
    LOCK_BEAT_SECONDS,
    LOCK_FILE,
    LOCK_STALE_SECONDS,
    FolderBusyError,
    clean_left_behind,
    folder_lock,
)

CACHE_ENV = "PGAE_LITE_CACHE"


class CheckpointMismatchError(PGAELiteError, ValueError):
    """An output folder holds a checkpoint of a different recipe; nothing is overwritten."""


class CorruptCheckpointError(PGAELiteError, ValueError):
    """A saved file is a folder, empty, truncated, foreign, holds more than tensors and data, or NaN weights."""


class SavedFileNotFoundError(PGAELiteError, FileNotFoundError):
    """No saved file (a checkpoint, a model) where one was named."""


def cache_dir() -> Path:
    """Root of every cache: ``$PGAE_LITE_CACHE``, else ``~/.cache/pgae_lite``; a file there, or the
    variable set but empty, is refused with one sentence (:class:`~pgae_lite.util.atomic_files.OutputError`)."""
    given = os.environ.get(CACHE_ENV)
    if given is not None and not given.strip():
        raise OutputError(f"{CACHE_ENV} is set but empty; unset it for ~/.cache/pgae_lite, or name a folder")
    folder = Path(given or Path.home() / ".cache" / "pgae_lite").expanduser()
    link = dangling_link(folder)
    if link is not None:
        raise OutputError(f"the cache folder {folder} ({CACHE_ENV}) cannot be used: {link} is a dangling link (to "
                          f"{os.readlink(link)}, which does not exist); remove the link, make its target, or name "
                          "another folder")
    if folder.exists() and not folder.is_dir():
        raise OutputError(f"the cache folder {folder} ({CACHE_ENV}) is a file; name a folder")
    return folder


def default_device() -> torch.device:
    """CUDA when present, else the CPU."""
    return torch.device("cuda" if torch.cuda.is_available() else "cpu")


#: Torch threads of every training on the CPU (the CAE's and PGAE's), whatever the caller set.
#: A parallel sum adds in an order that depends on the thread count, and a training amplifies
#: the last bits: a CAE trained on 1 and on 2 threads ends with other weights, so other visual
#: features and other PGAE models. One fixed count makes the data and the models the same on
#: every machine (tests/test_cae.py, tests/test_train.py). PGAE trains as fast on one thread as
#: on two; the CAE's convolutions are slower on one, once per cache (the book's results page, A2).
TRAINING_THREADS = 1


@contextlib.contextmanager
def training_threads(device: torch.device | str) -> Iterator[None]:
    """Run the block on :data:`TRAINING_THREADS` torch threads when ``device`` is the CPU
    (the caller's count is restored after); on a GPU nothing changes."""
    if torch.device(device).type != "cpu":
        yield
        return
    before = torch.get_num_threads()
    torch.set_num_threads(TRAINING_THREADS)
    try:
        yield
    finally:
        torch.set_num_threads(before)


def config_digest(obj) -> str:
    """12 hex digits of the SHA-1 of ``obj`` as JSON with sorted keys: a config's name in a cache.

    Objects JSON cannot write (none in our configs) are written as ``str(obj)``.
    """
    return hashlib.sha1(json.dumps(obj, sort_keys=True, default=str).encode()).hexdigest()[:12]


def array_digest(arrays: dict[str, np.ndarray]) -> str:
    """32 hex digits of a BLAKE2b over the names and bytes of ``arrays``."""
    h = hashlib.blake2b(digest_size=16)
    for k in sorted(arrays):
        h.update(k.encode())
        h.update(np.ascontiguousarray(arrays[k]).tobytes())
    return h.hexdigest()


def save_torch(obj, path: str | Path) -> None:
    """``torch.save(obj, path)``, atomically; :class:`~pgae_lite.util.atomic_files.OutputError` if it fails."""
    path = Path(path)
    make_folder(path.parent)
    with atomic_path(path) as tmp:
        try:
            torch.save(obj, tmp)
        except RuntimeError as e:   # torch: "enforce fail at inline_container.cc"
            raise OutputError(f"cannot write {path}: {why_failed(path, e)}; the old file, if "
                              "any, is unchanged") from None


def _not_finite(obj, name: str = "") -> list[str]:
    """The names (dotted) of the tensors and numbers in ``obj`` (nested dicts, lists) holding NaN or infinity."""
    if torch.is_tensor(obj):
        return [name] if obj.is_floating_point() and not bool(torch.isfinite(obj).all()) else []
    if isinstance(obj, float):
        return [] if math.isfinite(obj) else [name]
    if isinstance(obj, dict):
        return [n for k, v in obj.items() for n in _not_finite(v, f"{name}.{k}" if name else str(k))]
    if isinstance(obj, (list, tuple)):
        return [n for i, v in enumerate(obj) for n in _not_finite(v, f"{name}[{i}]")]
    return []


def load_torch(path: str | Path, keys: tuple[str, ...] = (), what: str = "checkpoint",
               finite: tuple[str, ...] = ()) -> dict:
    """A dict saved by :func:`save_torch`, read with ``weights_only=True``: the one reader of every saved file
    (models, the CAE, checkpoints, caches), and the checks they all get.

    Raises :class:`CorruptCheckpointError` naming the file if it is a folder, empty,
    truncated, not a torch file, holds other Python objects than tensors and
    plain data (never loaded: unpickling them can run code), lacks ``keys``, or holds NaN or infinity
    anywhere under the keys ``finite`` (weights, optimiser state, statistics; the first few named).
    A missing file is a :class:`SavedFileNotFoundError`.
    """
    path = Path(path)
    if path.is_dir():
        raise CorruptCheckpointError(f"{path} is a folder where a {what} (a file) should be; remove or rename "
                                     "the folder")
    if not path.is_file():
        raise SavedFileNotFoundError(f"no {what} at {path}")
    try:
        obj = torch.load(path, map_location="cpu", weights_only=True)
    except pickle.UnpicklingError as e:
        if "GLOBAL" in str(e):       # a class or function to import: refused
            raise CorruptCheckpointError(
                f"{path} holds Python objects other than tensors and plain data, so "
                f"it is not a pgae_lite {what}; weights_only=True refuses it, since "
                "unpickling it could run code") from None
        raise CorruptCheckpointError(f"{path} is not a readable {what} (not a "
                                     "torch file)") from None
    except Exception as e:  # EOFError (empty), RuntimeError (truncated zip), KeyError
        why = "empty" if path.stat().st_size == 0 else "truncated or damaged"
        raise CorruptCheckpointError(f"{path} is not a readable {what}: it is {why} "
                                     f"({type(e).__name__}); delete it to start "
                                     "again") from None
    missing = [k for k in keys if not isinstance(obj, dict) or k not in obj]
    if missing:
        raise CorruptCheckpointError(f"{path} is not a pgae_lite {what}: it lacks "
                                     f"{', '.join(missing)}")
    broken = [n for k in finite if isinstance(obj, dict) and k in obj for n in _not_finite(obj[k], k)]
    if broken:
        weights = "weights" if all(n.startswith("model.") for n in broken) else "values"
        raise CorruptCheckpointError(f"{path} holds non-finite {weights} (NaN or infinite) in "
                                     f"{', '.join(broken[:3])}{' ...' if len(broken) > 3 else ''}: the {what} "
                                     "cannot be used; train it again")
    return obj


def _names(names, at_most: int = 3) -> str:
    names = sorted(names)
    return ", ".join(names[:at_most]) + (f" and {len(names) - at_most} more" if len(names) > at_most else "")


def load_state(module: torch.nn.Module, state, path: str | Path, what: str = "model") -> torch.nn.Module:
    """``module`` with the saved weights ``state`` (a state dict read by :func:`load_torch`), or a
    :class:`CheckpointMismatchError` naming the file and the tensors that are missing, not the module's, or of
    another shape (another model's weights, another version's, or an altered file)."""
    if not isinstance(state, dict):
        raise CorruptCheckpointError(f"{path} holds no weights for the {what} (a {type(state).__name__}, not a "
                                     "dict of tensors); train it again")
    expected = module.state_dict()
    missing, extra = set(expected) - set(state), set(state) - set(expected)
    shapes = [f"{k} {tuple(state[k].shape)} (the {what}'s: {tuple(v.shape)})" for k, v in expected.items()
              if k in state and torch.is_tensor(v) and torch.is_tensor(state[k]) and state[k].shape != v.shape]
    problems = ([f"it lacks the tensor(s) {_names(missing)}"] if missing else []) + \
               ([f"it holds tensor(s) the {what} has not: {_names(extra)}"] if extra else []) + \
               ([f"tensor(s) of another shape: {_names(shapes, 2)}"] if shapes else [])
    if not problems:
        try:
            module.load_state_dict(state)
            return module
        except (RuntimeError, TypeError, AttributeError, ValueError) as e:
            problems = [(str(e).strip().splitlines() or [type(e).__name__])[-1].strip()[:160]]
    raise CheckpointMismatchError(f"{path} holds weights that do not fit the {what} its recipe describes "
                                  f"({'; '.join(problems)}): it was written by another version of the package "
                                  "or altered; train the model again")


def config_from(cls, settings, path: str | Path, what: str):
    """``cls(**settings)``: a saved config (a dataclass's dict) made a config again, or a
    :class:`CheckpointMismatchError` naming the file and the setting that this version does not know or refuses
    (an older or newer pgae_lite's file, or an altered one)."""
    if not isinstance(settings, dict):
        raise CheckpointMismatchError(f"{path} holds no {what} (a {type(settings).__name__}, not a dict of "
                                      "settings): it is not a pgae_lite file, or it was altered")
    known = {f.name for f in dataclasses.fields(cls)}
    unknown = [k for k in settings if k not in known]
    if unknown:
        raise CheckpointMismatchError(f"{path} holds {what} this pgae_lite does not know ({_names(map(str, unknown))}"
                                      f"; it knows {_names(known, 40)}): it was written by another version of the "
                                      "package or altered; train the model again")
    try:
        return cls(**settings)
    except (TypeError, ValueError) as e:       # a value of the wrong type or out of range: said in one sentence
        first = (str(e).strip().splitlines() or [type(e).__name__])[0]
        raise CheckpointMismatchError(f"{path} holds {what} this pgae_lite refuses ({first}); it was written by "
                                      "another version of the package or altered; train the model again") from None


# The names of pgae_lite.util.atomic_files and pgae_lite.util.folder_lock imported above stay importable from
# here (the package's modules and tests always imported them so); they are documented where they live.
__all__ = ["CACHE_ENV", "CheckpointMismatchError", "CorruptCheckpointError", "SavedFileNotFoundError",
           "TRAINING_THREADS", "array_digest", "cache_dir", "config_digest", "config_from", "default_device",
           "load_state", "load_torch", "save_torch", "training_threads"]
