"""Silencing pybullet's C-level console output (it would fill notebook cells)."""
from __future__ import annotations

import contextlib
import os
import sys
from typing import Iterator


@contextlib.contextmanager
def silenced(fd: int) -> Iterator[None]:
    """Send what C code writes to file descriptor ``fd`` (1 stdout, 2 stderr) to /dev/null."""
    (sys.stdout if fd == 1 else sys.stderr).flush()
    saved, devnull = os.dup(fd), os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, fd)
        yield
    finally:
        os.dup2(saved, fd)
        os.close(saved)
        os.close(devnull)
