"""The package's errors: one base class, so that a caller can catch every one of them.

Every error pgae_lite raises about what it was given (text, arguments, data,
checkpoints, models) is a :class:`PGAELiteError`; its message is one sentence
that names what was wrong and what is allowed. The command line prints it as
``error: ...`` and exits with status 2, without a traceback. Each class is also
a ``ValueError``, ``TypeError`` or ``RuntimeError``, so code that caught those
before still catches them.
"""
from __future__ import annotations


class PGAELiteError(Exception):
    """The package's errors about its input; the message says what is allowed."""


class ArgumentError(PGAELiteError, ValueError):
    """A public function got an argument of the right type but an unusable value."""


class ArgumentTypeError(PGAELiteError, TypeError):
    """A public function got an argument of the wrong type (1.5 or '3' for an int)."""


__all__ = ["ArgumentError", "ArgumentTypeError", "PGAELiteError"]
