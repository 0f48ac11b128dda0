"""One training run at a time in an output folder, and what dead runs left there removed (no paper section).

:func:`folder_lock` holds a folder's lock file while a run writes there: a second run fails with
:class:`FolderBusyError`, a dead run's lock is taken over, and a folder that cannot be written (a read-only
disk, a cache shared read-only) is read without a lock: nobody can write there, so there is nothing to
guard, and whatever the run then tries to write fails in one sentence.
"""
from __future__ import annotations

import contextlib
import errno
import os
import re
import socket
import threading
import time
import uuid
from pathlib import Path
from typing import Iterator

from pgae_lite.util.atomic_files import OutputError, alive, make_folder, why_failed
from pgae_lite.util.errors import PGAELiteError

LOCK_FILE = ".pgae_lite.lock"
LOCK_BEAT_SECONDS = 60      # a held lock's file is touched this often, so that
LOCK_STALE_SECONDS = 600    # another machine can tell a dead holder by a file this old
#: The errors of a folder nobody may write into: a read-only disk, no permission.
READ_ONLY = (errno.EROFS, errno.EACCES, errno.EPERM)


class FolderBusyError(PGAELiteError, RuntimeError):
    """Another live process is training into the same output folder."""


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
    return f"{host}:{pid}" if alive(int(pid)) else None


# What a run leaves when it is killed: its lock's link source, a taken-over lock, half-written files.
_LEFT_BEHIND = re.compile(rf"(?:{re.escape(LOCK_FILE)}|.+)\.(\d+)-[0-9a-f]{{8}}(?:\.tmp|\.stale)?")


def clean_left_behind(folder: Path) -> list[Path]:
    """Remove the lock and temporary files that dead processes left in ``folder`` (and below); the removed."""
    removed = []
    for path in folder.rglob("*"):
        hit = _LEFT_BEHIND.fullmatch(path.name)
        if hit and path.is_file() and not path.is_symlink() and int(hit.group(1)) != os.getpid() \
                and not alive(int(hit.group(1))):
            with contextlib.suppress(OSError):
                path.unlink()
                removed.append(path)
    return removed


def _beat(lock: Path, stop: threading.Event) -> None:
    """Touch ``lock`` every ``LOCK_BEAT_SECONDS`` until ``stop``: its holder is alive."""
    while not stop.wait(LOCK_BEAT_SECONDS):
        with contextlib.suppress(OSError):
            os.utime(lock)


def _remove(path: Path) -> None:
    """Remove ``path`` if it is there; a failure to (a read-only disk) never hides the error being handled."""
    with contextlib.suppress(OSError):
        path.unlink(missing_ok=True)


def _take(lock: Path, mine: Path, folder: Path) -> None:
    """Make ``lock`` a link to ``mine`` (atomic), taking over a dead holder's; FolderBusyError if alive."""
    while True:
        try:
            os.link(mine, lock)              # atomic: fails if a lock is there
            return
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


@contextlib.contextmanager
def folder_lock(folder: str | Path) -> Iterator[bool]:
    """Hold ``folder``'s lock file while the block runs: a second run there fails. Yields True when the
    lock is held; False when the folder exists but cannot be written (a read-only disk or no permission),
    so that the block may only read from it.

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
    except OSError as e:
        _remove(mine)
        if e.errno not in READ_ONLY:
            raise OutputError(f"cannot write the lock file {lock}: {why_failed(lock, e)}") from None
        mine = None                           # read-only: nobody writes here, so nothing to guard
    if mine is None:
        yield False
        return
    try:
        _take(lock, mine, Path(folder))
    except OSError as e:
        _remove(mine)
        raise OutputError(f"cannot write the lock file {lock}: {why_failed(lock, e)}") from None
    except BaseException:
        _remove(mine)
        raise
    clean_left_behind(lock.parent)
    stop = threading.Event()
    threading.Thread(target=_beat, args=(lock, stop), daemon=True).start()
    try:
        yield True
    finally:
        stop.set()
        with contextlib.suppress(OSError):
            if lock.read_text() == token:
                lock.unlink()
        _remove(mine)


__all__ = ["FolderBusyError", "LOCK_BEAT_SECONDS", "LOCK_FILE", "LOCK_STALE_SECONDS", "READ_ONLY",
           "clean_left_behind", "folder_lock"]
