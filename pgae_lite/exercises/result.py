"""What a check reports, and how every check runs and compares a student's code (no paper section).

:class:`CheckResult` is a short report: what matched; where and by how much it
did not, with a hint. The helpers run student code so that an error becomes a
failure line, never a traceback, and compare outputs with the reference.
"""
from __future__ import annotations

import math
import reprlib
from dataclasses import dataclass, field
from typing import Any, Callable, Sequence

import torch
from torch import nn


@dataclass(repr=False)
class CheckResult:
    """What a check found: truthy when everything matched; ``print`` it, or let Jupyter show it."""

    name: str
    passed: bool = True
    lines: list[str] = field(default_factory=list)

    def ok(self, text: str) -> CheckResult:
        self.lines.append(f"  ✓ {text}")
        return self

    def fail(self, text: str, hint: str | None = None) -> CheckResult:
        """Record a failure (and a hint); returns the result, so a check can ``return result.fail(...)``."""
        self.passed = False
        self.lines.append(f"  ✗ {text}" + (f"\n      hint: {hint}" if hint else ""))
        return self

    def note(self, text: str) -> CheckResult:
        self.lines.append(f"  · {text}")
        return self

    def __bool__(self) -> bool:
        return self.passed

    def __str__(self) -> str:
        return "\n".join([f"{self.name}: {'passed' if self.passed else 'not yet, see the ✗ lines'}", *self.lines])

    __repr__ = __str__


RAISED = object()  # what _call returns when student code raised (failure recorded)


def _call(result: CheckResult, what: str, fn: Callable, *args: Any) -> Any:
    """Run student code; an exception becomes a failure line, never a traceback."""
    try:
        return fn(*args)
    except Exception as error:  # noqa: BLE001 - an error in student code is a finding
        result.fail(f"{what} raised {type(error).__name__}: {error}")
        return RAISED


def _shape(t: Any) -> str:
    return f"shape {tuple(t.shape)}" if isinstance(t, torch.Tensor) else f"type {type(t).__name__}"


def _returned(out: Any) -> str:
    """In words: None, one tensor of shape (5, 4), a list of 3 items."""
    if out is None:
        return "None"
    if isinstance(out, torch.Tensor):
        return f"one tensor of shape {tuple(out.shape)}"
    if isinstance(out, (tuple, list)):
        return f"a {type(out).__name__} of {len(out)} items"
    return f"a {type(out).__name__}"


def _pair(result: CheckResult, out: Any, names: str, who: str, shape: tuple) -> bool:
    """Whether ``out`` is a pair; if not, a failure line says what it was instead."""
    if out is RAISED:
        return False
    if isinstance(out, (tuple, list)) and len(out) == 2:
        return True
    stub = f"a stub returns None: end with return {names}" if out is None else None
    result.fail(f"{who} returned {_returned(out)}; expected the pair ({names}), "
                f"two tensors of shape {shape}", stub)
    return False


def _value_problem(got: torch.Tensor, like: torch.Tensor) -> str | None:
    """What is wrong with a tensor of the right shape (dtype, device, NaN, inf)."""
    if got.dtype != like.dtype or got.device != like.device:
        return (f"is a {got.dtype} tensor on {got.device}; expected {like.dtype} "
                f"on {like.device}, as the inputs")
    bad = ~torch.isfinite(got.detach())
    if not bad.any():
        return None
    at = tuple(bad.nonzero()[0].tolist())
    return (f"has {int(bad.sum())} NaN or infinite entries of {bad.numel()}; "
            f"the first is at index {at}: {got[at].item()}")


def _unchanged(result: CheckResult, who: str, given: dict[str, torch.Tensor],
               kept: dict[str, torch.Tensor]) -> None:
    """Fail, naming them, if student code changed its copies of ``kept`` in place."""
    def same(a: Any, b: torch.Tensor) -> bool:
        return (isinstance(a, torch.Tensor) and a.dtype == b.dtype
                and a.device == b.device and torch.equal(a, b))
    changed = [n for n, t in kept.items() if not same(given.get(n), t)]
    if changed:
        result.fail(f"{who} changed {', '.join(changed)} in place; the check compares "
                    "with the reference computed on the unchanged originals",
                    "compute new tensors (no +=, .mul_(), .copy_(), ...)")


def _compare(result: CheckResult, name: str, got: Any, expected: torch.Tensor) -> bool:
    """One output against the reference: type, shape, then values (where, and by how much)."""
    if not isinstance(got, torch.Tensor) or got.shape != expected.shape:
        result.fail(f"{name} has {_shape(got)}; expected a tensor of shape {tuple(expected.shape)}")
        return False
    problem = _value_problem(got, expected)
    if problem:
        result.fail(f"{name} {problem}")
        return False
    diff = (got.detach().double() - expected.double()).abs().nan_to_num(math.inf)
    if diff.max() <= 1e-5:
        result.ok(f"{name} {tuple(got.shape)} matches the reference (largest difference {diff.max():.1e})")
        return True
    at = tuple(int(k) for k in torch.unravel_index(diff.argmax(), diff.shape))
    result.fail(f"{name} differs at {int((diff > 1e-5).sum())} of {diff.numel()} entries; the largest difference, "
                f"{diff[at]:.4f}, is at index {at}: got {got[at]:.4f}, expected {expected[at]:.4f}")
    return False


def _diagnose(result: CheckResult, got: Sequence, mistakes: list[tuple[str, tuple]], equation: str) -> None:
    """Name the first known mistake that reproduces the student's outputs exactly."""
    def same(a: Any, b: torch.Tensor) -> bool:
        return (isinstance(a, torch.Tensor) and a.shape == b.shape
                and torch.allclose(a.detach().double(), b.double(), atol=1e-5))
    hint = next((h for h, outputs in mistakes if all(same(g, o) for g, o in zip(got, outputs))), None)
    result.note(f"diagnosis: {hint}" if hint else f"compare each term with the equation: {equation}")


def _build(result: CheckResult, factory: Callable, *sizes: int,
           name: str = "factory") -> nn.Module | None:
    """The student's module, ``factory(*sizes)``, or None after a failure line."""
    module = _call(result, f"{name}{sizes}", factory, *sizes)
    if isinstance(module, nn.Module) or module is RAISED:
        return None if module is RAISED else module
    result.fail(f"{name}{sizes} returned {_returned(module)}",
                "return an nn.Module, so that it trains")
    return None


def _numbers(result: CheckResult, values: Any, what: str) -> list[float] | None:
    """``values`` as floats, or None after a failure line: not finite numbers."""
    try:  # a string is no number here, though float("0.5") reads it: NaN, so it fails
        numbers = [math.nan if isinstance(v, (str, bytes)) else float(v)
                   for v in values]
    except (TypeError, ValueError, OverflowError):
        numbers = [math.nan]
    if isinstance(values, (str, bytes)) or not all(map(math.isfinite, numbers)):
        result.fail(f"{what} must be finite numbers; got {reprlib.repr(values)}")
        return None
    return numbers


__all__ = ["CheckResult"]
