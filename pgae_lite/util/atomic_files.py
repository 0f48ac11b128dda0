"""Writes that never leave half a file or half a folder, and fail in one sentence (no paper section).

- :func:`make_folder`: ``mkdir -p`` whose failures (a file, a dangling link in the way, a read-only
  disk, a full disk) are one sentence (:class:`OutputError`);
- :func:`atomic_path`, :func:`atomic_write`, :func:`atomic_write_text`: a file is written under a
  temporary name beside its place, then renamed onto it in one step, so a reader (or a crash) never
  meets half a file; a write never goes through a symbolic link;
- :func:`atomic_folder`: the same for a whole folder of files (``export-web``'s): written into a
  temporary sibling, moved into place when complete; a failure leaves the folder as it was.

It imports nothing from ``pgae_lite`` but its errors, so any module may import it without a cycle.
"""
from __future__ import annotations

import contextlib
import errno
import os
import re
import shutil
import uuid
from pathlib import Path
from typing import IO, Iterator

from pgae_lite.util.errors import PGAELiteError


class OutputError(PGAELiteError, OSError):
    """A file or folder cannot be written (full disk, read-only, a file in the way)."""


def why_failed(path: Path, error: BaseException) -> str:
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


def dangling_link(path: Path) -> Path | None:
    """``path`` or the first of its parents that is a symbolic link to nothing (or a loop of links); None if
    there is none."""
    for part in (path, *path.parents):
        with contextlib.suppress(OSError):
            if part.is_symlink() and not part.exists():
                return part
    return None


def make_folder(folder: str | Path) -> Path:
    """``mkdir -p`` that fails with one clear sentence (:class:`OutputError`)."""
    folder = Path(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        link = dangling_link(folder)
        if link is not None:
            raise OutputError(f"cannot use {folder} as an output folder: {link} is a dangling link (to "
                              f"{os.readlink(link)}, which does not exist); remove the link or name another "
                              "folder") from None
        raise OutputError(f"cannot use {folder} as an output folder: a file of that "
                          "name is in the way") from None
    except OSError as e:
        raise OutputError(f"cannot create the output folder {folder}: "
                          f"{why_failed(folder, e)}") from None
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
        raise OutputError(f"cannot write {path}: {why_failed(path, e)}; the old file, if "
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


def alive(pid: int) -> bool:
    """Whether a process ``pid`` runs on this machine (another user's counts)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        pass                          # alive, another user's
    return True


@contextlib.contextmanager
def atomic_folder(folder: str | Path) -> Iterator[Path]:
    """A new temporary folder beside ``folder`` to write a whole folder's files into; when the block ends,
    they are moved into ``folder`` (created if missing), replacing those of the same names.

    A missing or empty ``folder`` is replaced by the temporary one in one rename, so a reader never meets it
    half-written; otherwise each of its entries is renamed into place (files it holds that the block did not
    write are kept). If the block raises, the temporary folder is removed and ``folder`` is left as it was.
    Temporary folders that dead processes left beside it are removed first.
    """
    folder = Path(folder)
    parent = make_folder(folder.parent)
    left = re.compile(rf"{re.escape(folder.name)}\.(\d+)-[0-9a-f]{{8}}\.(?:tmp|old)")
    for path in parent.glob(f"{glob_escape(folder.name)}.*"):
        hit = left.fullmatch(path.name)
        if hit and path.is_dir() and not path.is_symlink() and not alive(int(hit.group(1))):
            shutil.rmtree(path, ignore_errors=True)
    stem = f"{folder.name}.{os.getpid()}-{uuid.uuid4().hex[:8]}"
    tmp, old = parent / f"{stem}.tmp", parent / f"{stem}.old"
    try:
        tmp.mkdir()
    except OSError as e:
        raise OutputError(f"cannot write the folder {folder}: {why_failed(tmp, e)}") from None
    try:
        yield tmp
        _move_in(tmp, folder, old)
    except OSError as e:
        if isinstance(e, OutputError):
            raise
        raise OutputError(f"cannot write the folder {folder}: {why_failed(folder, e)}; nothing in it "
                          "was changed") from None
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
        shutil.rmtree(old, ignore_errors=True)


def glob_escape(name: str) -> str:
    """``name`` with glob's special characters made literal."""
    return re.sub(r"([*?\[])", r"[\1]", name)


def _move_in(tmp: Path, folder: Path, old: Path) -> None:
    """Move ``tmp``'s entries into ``folder``: in one rename if ``folder`` is missing or empty."""
    with contextlib.suppress(OSError):
        os.replace(tmp, folder)        # rename(2) replaces a missing or empty folder, in one step
        return
    make_folder(folder)
    old.mkdir()
    for entry in sorted(tmp.iterdir()):
        target = folder / entry.name
        if target.is_symlink() or target.exists():
            os.replace(target, old / entry.name)          # kept until the new one is in place
        os.replace(entry, target)


__all__ = ["OutputError", "atomic_folder", "atomic_path", "atomic_write", "atomic_write_text", "dangling_link",
           "glob_escape", "make_folder", "why_failed"]
