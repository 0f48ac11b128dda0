"""Shared plumbing: the cache folder, the device, atomic writes, config digests (no paper section).

What several modules need and none of them owns. It imports nothing from
``pgae_lite``, so any module may import it without a cycle.

- :func:`cache_dir`: the root of every cache (``$PGAE_LITE_CACHE``);
- :func:`default_device`: CUDA when present, else the CPU;
- :func:`training_threads`: a training on the CPU runs on a fixed number of torch
  threads, so that a seed gives the same model on any machine;
- :func:`atomic_path`, :func:`atomic_write`, :func:`atomic_write_text`: a file
  is written under a temporary name beside its place, then renamed onto it in
  one step, so a reader (or a crash) never meets half a file;
- :func:`config_digest`: the short digest of a config that names its cache entry;
  :func:`array_digest`: a digest of arrays' contents (a cache file's check);
- :func:`save_torch`, :func:`load_torch`: checkpoints written atomically and read
  with ``weights_only=True``; a write that fails (a full disk, a read-only
  folder) raises :class:`OutputError`, a damaged or unsafe file
  :class:`CorruptCheckpointError`, each one sentence naming the file;
- :func:`folder_lock`: one training run at a time in an output folder (and what dead runs left, removed);
- :class:`CheckpointMismatchError`: a file holds the work of another recipe.
"""
from __future__ import annotations

import contextlib
import errno
import hashlib
import json
import os
import pickle
import re
import shutil
import socket
import threading
import time
import uuid
from pathlib import Path
from typing import IO, Iterator

import numpy as np
import torch

from pgae_lite.util.errors import PGAELiteError

CACHE_ENV = "PGAE_LITE_CACHE"


class CheckpointMismatchError(PGAELiteError, ValueError):
    """An output folder holds a checkpoint of a different recipe; nothing is overwritten."""


class CorruptCheckpointError(PGAELiteError, ValueError):
    """A checkpoint is empty, truncated, foreign, or holds more than tensors, data."""


class OutputError(PGAELiteError, OSError):
    """A file or folder cannot be written (full disk, read-only, a file in the way)."""


class FolderBusyError(PGAELiteError, RuntimeError):
    """Another live process is training into the same output folder."""


def cache_dir() -> Path:
    """Root of every cache: ``$PGAE_LITE_CACHE``, else ``~/.cache/pgae_lite``; a file there, or the
    variable set but empty, is refused with one sentence (:class:`OutputError`)."""
    given = os.environ.get(CACHE_ENV)
    if given is not None and not given.strip():
        raise OutputError(f"{CACHE_ENV} is set but empty; unset it for ~/.cache/pgae_lite, or name a folder")
    folder = Path(given or Path.home() / ".cache" / "pgae_lite").expanduser()
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


def _why(path: Path, error: BaseException) -> str:
    """Why a write to ``path`` failed, in words: a full disk said as such."""
    try:
        free = shutil.disk_usage(path.parent).free
    except OSError:
        free = None
    full = free is not None and free < 1 << 24                  # under 16 MiB left
    code = getattr(error, "errno", None)                       # an error without a code may be a full disk
    if code == errno.ENOSPC or (full and code is None):
        return f"the disk is full ({free} bytes free)"
    if isinstance(error, OSError) and error.strerror:
        return error.strerror
    text = str(error).strip()
    return text.splitlines()[0] if text else type(error).__name__


def make_folder(folder: str | Path) -> Path:
    """``mkdir -p`` that fails with one clear sentence (:class:`OutputError`)."""
    folder = Path(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise OutputError(f"cannot use {folder} as an output folder: a file of that "
                          "name is in the way") from None
    except OSError as e:
        raise OutputError(f"cannot create the output folder {folder}: "
                          f"{_why(folder, e)}") from None
    return folder


@contextlib.contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """A temporary path beside ``path`` to write to; it replaces ``path`` when the block ends.

    The rename (``os.replace``) is atomic, so ``path`` holds either its old
    contents or the whole new file, never part of it. A symbolic link at ``path``
    is refused (:class:`OutputError`): a write never goes through a link. If the block raises, the
    temporary file is removed and ``path`` is left as it was. The temporary
    name holds the process id and a random part: parallel writers never share one.
    """
    path = Path(path)
    if path.is_symlink():       # a link planted in a shared folder must not redirect the write
        raise OutputError(f"refusing to write {path}: it is a symbolic link (to {os.readlink(path)}); "
                          "remove the link or write to another folder")
    if path.is_dir():
        raise OutputError(f"cannot write {path}: it is a folder; name a file")
    tmp = path.with_name(f"{path.name}.{os.getpid()}-{uuid.uuid4().hex[:8]}.tmp")
    try:
        yield tmp
        os.replace(tmp, path)
    except OutputError:
        raise
    except OSError as e:        # full disk, read-only folder, a file for a folder
        raise OutputError(f"cannot write {path}: {_why(path, e)}; the old file, if "
                          "any, is unchanged") from None
    finally:
        with contextlib.suppress(OSError):
            tmp.unlink(missing_ok=True)     # only left if the block (or rename) failed


@contextlib.contextmanager
def atomic_write(path: str | Path, mode: str = "wb", **open_kwargs) -> Iterator[IO]:
    """``open(path, mode)`` for writing, atomically (see :func:`atomic_path`)."""
    with atomic_path(path) as tmp, open(tmp, mode, **open_kwargs) as f:
        yield f


def atomic_write_text(path: str | Path, text: str, encoding: str = "utf-8") -> None:
    """Write ``text`` to ``path`` atomically (see :func:`atomic_path`)."""
    with atomic_write(path, "w", encoding=encoding) as f:
        f.write(text)


def save_torch(obj, path: str | Path) -> None:
    """``torch.save(obj, path)``, atomically; :class:`OutputError` if it fails."""
    path = Path(path)
    make_folder(path.parent)
    with atomic_path(path) as tmp:
        try:
            torch.save(obj, tmp)
        except RuntimeError as e:   # torch: "enforce fail at inline_container.cc"
            raise OutputError(f"cannot write {path}: {_why(path, e)}; the old file, if "
                              "any, is unchanged") from None


def load_torch(path: str | Path, keys: tuple[str, ...] = (),
               what: str = "checkpoint") -> dict:
    """A dict saved by :func:`save_torch`, read with ``weights_only=True``.

    Raises :class:`CorruptCheckpointError` naming the file if it is empty,
    truncated, not a torch file, holds other Python objects than tensors and
    plain data (never loaded: unpickling them can run code), or lacks ``keys``.
    """
    path = Path(path)
    if not path.is_file():
        folder = " (it is a folder)" if path.is_dir() else ""
        raise FileNotFoundError(f"no {what} at {path}{folder}")
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
    return obj


LOCK_FILE = ".pgae_lite.lock"
LOCK_BEAT_SECONDS = 60      # a held lock's file is touched this often, so that
LOCK_STALE_SECONDS = 600    # another machine can tell a dead holder by a file this old


def _dead(pid: int) -> bool:
    """Whether no process ``pid`` runs on this machine."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    except PermissionError:
        pass                          # alive, another user's
    return False


def _holder(lock: Path) -> str | None:
    """``host:pid`` of a lock's live holder; None if the lock is stale (or gone)."""
    try:
        host, _, pid = lock.read_text().strip().rpartition(":")
    except OSError:
        return None
    if host != socket.gethostname():  # another machine's process: alive while it touches its lock
        with contextlib.suppress(OSError):
            if time.time() - lock.stat().st_mtime > LOCK_STALE_SECONDS:
                return None
        return f"{host}:{pid}"
    if not pid.isdigit() or int(pid) == os.getpid():
        return None                   # unreadable, or left by this very process
    return None if _dead(int(pid)) else f"{host}:{pid}"


# What a run leaves when it is killed: its lock's link source, a taken-over lock, half-written files.
_LEFT_BEHIND = re.compile(rf"(?:{re.escape(LOCK_FILE)}|.+)\.(\d+)-[0-9a-f]{{8}}(?:\.tmp|\.stale)?")


def clean_left_behind(folder: Path) -> list[Path]:
    """Remove the lock and temporary files that dead processes left in ``folder`` (and below); the removed."""
    removed = []
    for path in folder.rglob("*"):
        hit = _LEFT_BEHIND.fullmatch(path.name)
        if hit and path.is_file() and not path.is_symlink() and int(hit.group(1)) != os.getpid() \
                and _dead(int(hit.group(1))):
            with contextlib.suppress(OSError):
                path.unlink()
                removed.append(path)
    return removed


def _beat(lock: Path, stop: threading.Event) -> None:
    """Touch ``lock`` every ``LOCK_BEAT_SECONDS`` until ``stop``: its holder is alive."""
    while not stop.wait(LOCK_BEAT_SECONDS):
        with contextlib.suppress(OSError):
            os.utime(lock)


@contextlib.contextmanager
def folder_lock(folder: str | Path) -> Iterator[None]:
    """Hold ``folder``'s lock file while the block runs: a second run there fails.

    The lock file holds ``host:pid``; a lock whose process has died is taken over (on another
    machine, one not touched for ``LOCK_STALE_SECONDS``: its holder touches it every
    ``LOCK_BEAT_SECONDS``), and the lock and temporary files that dead runs left in the
    folder are removed (:func:`clean_left_behind`).
    """
    lock = make_folder(folder) / LOCK_FILE
    token = f"{socket.gethostname()}:{os.getpid()}"
    mine = lock.with_name(f"{LOCK_FILE}.{os.getpid()}-{uuid.uuid4().hex[:8]}")
    try:
        mine.write_text(token)
        while True:
            try:
                os.link(mine, lock)              # atomic: fails if a lock is there
                break
            except FileExistsError:
                holder = _holder(lock)
                if holder is not None:
                    raise FolderBusyError(
                        f"{folder} is in use by another run (process {holder}, lock "
                        f"file {lock}); wait for it, use another folder, or delete the "
                        "lock file if that process is gone") from None
                stale = lock.with_name(f"{mine.name}.stale")
                with contextlib.suppress(FileNotFoundError):
                    os.replace(lock, stale)      # one taker wins; the others retry
                    stale.unlink()
    except OSError as e:
        mine.unlink(missing_ok=True)
        raise OutputError(f"cannot write the lock file {lock}: "
                          f"{_why(lock, e)}") from None
    except BaseException:
        mine.unlink(missing_ok=True)
        raise
    clean_left_behind(lock.parent)
    stop = threading.Event()
    threading.Thread(target=_beat, args=(lock, stop), daemon=True).start()
    try:
        yield
    finally:
        stop.set()
        with contextlib.suppress(OSError):
            if lock.read_text() == token:
                lock.unlink()
        mine.unlink(missing_ok=True)


__all__ = ["CACHE_ENV", "CheckpointMismatchError", "CorruptCheckpointError",
           "FolderBusyError", "OutputError", "array_digest", "atomic_path",
           "atomic_write", "atomic_write_text", "cache_dir", "clean_left_behind", "config_digest",
           "default_device", "folder_lock", "load_torch", "make_folder", "save_torch",
           "training_threads", "TRAINING_THREADS"]
