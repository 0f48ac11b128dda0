"""Shared plumbing: the cache folder, the device, atomic writes, config digests (no paper section).

What several modules need and none of them owns. It imports nothing from
``pgae_lite``, so any module may import it without a cycle.

- :func:`cache_dir`: the root of every cache (``$PGAE_LITE_CACHE``);
- :func:`default_device`: CUDA when present, else the CPU;
- :func:`atomic_path`, :func:`atomic_write`, :func:`atomic_write_text`: a file
  is written under a temporary name beside its place, then renamed onto it in
  one step, so a reader (or a crash) never meets half a file;
- :func:`config_digest`: the short digest of a config that names its cache entry;
- :class:`CheckpointMismatchError`: a file holds the work of another recipe.
"""
from __future__ import annotations

import contextlib
import hashlib
import json
import os
import uuid
from pathlib import Path
from typing import IO, Iterator

import torch

from .errors import PGAELiteError

CACHE_ENV = "PGAE_LITE_CACHE"


class CheckpointMismatchError(PGAELiteError, ValueError):
    """An output folder holds a checkpoint of a different recipe; nothing is overwritten."""


def cache_dir() -> Path:
    """Root of every cache: ``$PGAE_LITE_CACHE``, else ``~/.cache/pgae_lite``."""
    return Path(os.environ.get(CACHE_ENV) or Path.home() / ".cache" / "pgae_lite").expanduser()


def default_device() -> torch.device:
    """CUDA when present, else the CPU."""
    return torch.device("cuda" if torch.cuda.is_available() else "cpu")


def config_digest(obj) -> str:
    """12 hex digits of the SHA-1 of ``obj`` as JSON with sorted keys: a config's name in a cache.

    Objects JSON cannot write (none in our configs) are written as ``str(obj)``.
    """
    return hashlib.sha1(json.dumps(obj, sort_keys=True, default=str).encode()).hexdigest()[:12]


@contextlib.contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """A temporary path beside ``path`` to write to; it replaces ``path`` when the block ends.

    The rename (``os.replace``) is atomic, so ``path`` holds either its old
    contents or the whole new file, never part of it. If the block raises, the
    temporary file is removed and ``path`` is left as it was. The temporary
    name holds the process id and a random part: parallel writers never share one.
    """
    path = Path(path)
    tmp = path.with_name(f"{path.name}.{os.getpid()}-{uuid.uuid4().hex[:8]}.tmp")
    try:
        yield tmp
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)     # only left if the block (or the rename) failed


@contextlib.contextmanager
def atomic_write(path: str | Path, mode: str = "wb", **open_kwargs) -> Iterator[IO]:
    """``open(path, mode)`` for writing, atomically (see :func:`atomic_path`)."""
    with atomic_path(path) as tmp, open(tmp, mode, **open_kwargs) as f:
        yield f


def atomic_write_text(path: str | Path, text: str, encoding: str = "utf-8") -> None:
    """Write ``text`` to ``path`` atomically (see :func:`atomic_path`)."""
    with atomic_write(path, "w", encoding=encoding) as f:
        f.write(text)


__all__ = ["CACHE_ENV", "CheckpointMismatchError", "atomic_path", "atomic_write", "atomic_write_text",
           "cache_dir", "config_digest", "default_device"]
