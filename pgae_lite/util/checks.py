"""Argument checks of the public functions: whole numbers in a range, types, devices, folders.

No paper section: plumbing for the command line, :mod:`~pgae_lite.runs.reproduce`,
:mod:`~pgae_lite.evaluate.table1` and the playground. Each check returns the value it
accepts, or raises one sentence that names the argument, the value given and
what is allowed (:class:`~pgae_lite.util.errors.ArgumentError`, or
:class:`~pgae_lite.util.errors.ArgumentTypeError` for a wrong type).
"""
from __future__ import annotations

import fnmatch
import math
import os
from numbers import Integral, Real
from pathlib import Path

from pgae_lite.util.errors import ArgumentError, ArgumentTypeError

#: The largest seed: numpy's generators take seeds 0 to 2**32 - 1.
MAX_SEED = 2 ** 32 - 1
#: The device types the package runs on.
DEVICE_TYPES = ("cpu", "cuda", "mps")
#: :func:`whole_number`'s messages as templates (``str.format``, named fields); the page fills the same ones.
MESSAGES: dict[str, str] = {
    "whole_number_type": "{name} must be {allowed}; got {value} ({type})",
    "whole_number_range": "{name} must be {allowed}; got {value}",
    "whole_number_at_least": "a whole number >= {low}",
    "whole_number_between": "a whole number from {low} to {high}",
}


def whole_number(name: str, value, low: int, high: int | None = None) -> int:
    """``value`` as an int when it is a whole number from ``low`` to ``high``.

    A bool, a float (even 3.0) or a string is refused with an ArgumentTypeError.
    """
    if high is None:
        allowed = MESSAGES["whole_number_at_least"].format(low=str(low))
    else:
        allowed = MESSAGES["whole_number_between"].format(low=str(low), high=str(high))
    if isinstance(value, bool) or not isinstance(value, Integral):
        raise ArgumentTypeError(MESSAGES["whole_number_type"].format(name=name, allowed=allowed, value=repr(value),
                                                                     type=type(value).__name__))
    if value < low or (high is not None and value > high):
        raise ArgumentError(MESSAGES["whole_number_range"].format(name=name, allowed=allowed, value=repr(value)))
    return int(value)


def positive_number(name: str, value) -> float:
    """``value`` as a float when it is a finite number > 0 (a bool is refused)."""
    if isinstance(value, bool) or not isinstance(value, Real):
        raise ArgumentTypeError(f"{name} must be a number > 0; got {value!r} "
                                f"({type(value).__name__})")
    if not math.isfinite(value) or value <= 0:
        raise ArgumentError(f"{name} must be a finite number > 0; got {value!r}")
    return float(value)


def shown(value) -> str:
    """``value`` for a message: its type and repr, or only its type if that is long."""
    text = repr(value)
    if len(text) > 60 or "\n" in text:
        return f"a {type(value).__name__}"
    return f"{type(value).__name__} {text}"


def instance_of(name: str, value, kind, what: str, optional: bool = False):
    """``value`` when it is a ``kind`` (or None, if ``optional``); ``what`` in words."""
    if (value is None and optional) or isinstance(value, kind):
        return value
    wanted = what + (" or None" if optional else "")
    raise ArgumentTypeError(f"{name} must be {wanted}; got {shown(value)}")


def torch_device(name: str, device) -> str | None:
    """``device`` when torch has it here (cpu, cuda, cuda:N, mps); None stays None."""
    import torch

    if device is None:
        return None
    choices = "cpu, cuda, cuda:N or mps (or leave it out: CUDA if present, else CPU)"
    instance_of(name, device, (str, torch.device), f"a torch device: {choices}")
    try:
        parsed = torch.device(device)
    except RuntimeError:
        raise ArgumentError(f"{name} {device!r} is not a torch device; "
                            f"use {choices}") from None
    available = {"cpu": True, "cuda": torch.cuda.is_available(),
                 "mps": torch.backends.mps.is_available()}
    if parsed.type not in DEVICE_TYPES:
        raise ArgumentError(f"{name} {device!r} is not a device this package runs on; "
                            f"use {choices}")
    if not available[parsed.type]:
        raise ArgumentError(f"{name} {device!r} is not available: torch finds no "
                            f"{parsed.type} device on this machine; use cpu, or leave "
                            f"{name} out")
    count = torch.cuda.device_count()
    if parsed.type == "cuda" and parsed.index is not None and parsed.index >= count:
        raise ArgumentError(f"{name} {device!r} does not exist: this machine has "
                            f"{count} CUDA device(s), cuda:0 to cuda:{count - 1}")
    return str(device)


#: What a run leaves in a folder it writes (its lock, temporary files), whatever the command: never foreign.
LEFT_BY_A_RUN = (".pgae_lite.lock*", "*.tmp", "*.stale")


def _path(name: str, value, default: str | None) -> Path:
    """``value`` as a Path: a str or PathLike, not empty text, without a NUL character."""
    instance_of(name, value, (str, os.PathLike), "a folder (str or Path)")
    text = os.fspath(value)
    if not isinstance(text, str) or not text.strip():
        leave = f", or leave {name} out for the default: {default}" if default else ""
        raise ArgumentError(f"{name} is empty text (an unset variable?); give a folder{leave}")
    if "\0" in text:
        raise ArgumentError(f"{name} {text!r} holds a NUL character, which no file name may hold; give a folder")
    return Path(text).expanduser()


def _first_existing(path: Path, name: str) -> Path:
    """``path`` or its nearest parent that exists; a dangling link or a file on the way is refused."""
    for part in (path, *path.parents):
        try:
            if part.is_symlink() and not part.exists():
                where = "is" if part == path else f"cannot be made: {part} is"
                raise ArgumentError(f"{name} {path} {where} a dangling link (to {os.readlink(part)}, which does "
                                    "not exist); remove the link, make its target, or name another folder")
            if part.exists():
                if not part.is_dir():
                    where = "is a file" if part == path else f"cannot be made: {part} is a file"
                    raise ArgumentError(f"{name} {path} {where}, not a folder; name a folder")
                return part
        except OSError as e:                     # a name too long, a loop of links, no permission to look
            raise ArgumentError(f"{name} {path} cannot be used: {e.strerror or e}; name another folder") from None
    return Path("/")


def output_folder(name: str, value, command: str, written: tuple[str, ...] = (), marker: str | None = None,
                  outside: dict[str, Path] | None = None, default: str | None = None) -> Path:
    """``value`` (the folder ``command`` writes into), resolved, once known to be one it may write into: the one
    check of every output folder of the command line and of the functions behind it.

    Refused, each in one sentence (:class:`~pgae_lite.util.errors.ArgumentError`): not a str or path, empty
    text (an unset variable), a NUL character, a file (or a file on its way), a dangling link (or one on its
    way), a folder inside one of ``outside`` (a description -> a folder, e.g. ``{"the repository": ROOT}``),
    and a folder that holds files the command did not write: it is new or empty, holds ``marker`` (a file the
    command writes first), or holds only entries whose names match ``written`` (glob patterns; a run's lock
    and temporary files always do). ``default``: what leaving it out gives, for the message."""
    path = _path(name, value, default)
    try:
        out = path.resolve()
    except (OSError, RuntimeError):              # a loop of links: said by _first_existing
        out = path.absolute()
    for what, folder in (outside or {}).items():
        folder = Path(folder).resolve()
        if out == folder or folder in out.parents:
            raise ArgumentError(f"{name} {out} is inside {what} ({folder}); write it outside {what}, e.g. "
                                f"/tmp/{out.name}")
    _first_existing(path, name)
    if not out.is_dir():
        return out
    try:
        entries = sorted(p.name for p in out.iterdir())
    except OSError as e:
        raise ArgumentError(f"{name} {out} cannot be read: {e.strerror or e}; name another folder") from None
    if marker is not None and marker in entries:
        return out
    foreign = [e for e in entries if not any(fnmatch.fnmatchcase(e, p) for p in (*written, *LEFT_BY_A_RUN))]
    if foreign:
        shown_names = ", ".join(foreign[:3]) + (f" and {len(foreign) - 3} more" if len(foreign) > 3 else "")
        raise ArgumentError(f"{name} {out} is a non-empty folder that {command} did not make: it holds files it "
                            f"did not write ({shown_names}); choose a new or empty folder, so that none of "
                            "them is overwritten")
    return out


def input_folder(name: str, value, what: str = "folder") -> Path:
    """``value`` (a folder a command reads), resolved, once known to be an existing folder: empty text, a
    missing path, a file or a dangling link are refused in one sentence."""
    path = _path(name, value, None)
    _first_existing(path, name)
    if not path.is_dir():
        raise ArgumentError(f"{name} {path}: no such {what}; name an existing one")
    return path.resolve()


__all__ = ["DEVICE_TYPES", "LEFT_BY_A_RUN", "MAX_SEED", "input_folder", "instance_of", "output_folder",
           "positive_number", "shown", "torch_device", "whole_number"]
