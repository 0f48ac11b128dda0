"""Argument checks of the public functions: whole numbers in a range, types, devices.

No paper section: plumbing for the command line, :mod:`~pgae_lite.runs.reproduce`,
:mod:`~pgae_lite.evaluate.table1` and the playground. Each check returns the value it
accepts, or raises one sentence that names the argument, the value given and
what is allowed (:class:`~pgae_lite.util.errors.ArgumentError`, or
:class:`~pgae_lite.util.errors.ArgumentTypeError` for a wrong type).
"""
from __future__ import annotations

import math
from numbers import Integral, Real

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


__all__ = ["DEVICE_TYPES", "MAX_SEED", "instance_of", "positive_number", "shown",
           "torch_device", "whole_number"]
