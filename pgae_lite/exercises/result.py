"""What a check reports, and how every check runs and compares a student's code (no paper section).

:class:`CheckResult` is a short report: what matched; where and by how much it
did not, with a hint. The helpers run student code so that an error becomes a
failure line, never a traceback, and compare outputs with the reference.
"""
from __future__ import annotations

import math
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


def _call(result: CheckResult, what: str, fn: Callable, *args: Any) -> Any:
    """Run student code; an exception becomes a failure line, never a traceback."""
    try:
        return fn(*args)
    except Exception as error:  # noqa: BLE001 - an error in student code is a finding
        result.fail(f"{what} raised {type(error).__name__}: {error}")
        return None


def _shape(t: Any) -> str:
    return f"shape {tuple(t.shape)}" if isinstance(t, torch.Tensor) else f"type {type(t).__name__}"


def _pair(result: CheckResult, out: Any, names: str) -> bool:
    if out is None or (isinstance(out, (tuple, list)) and len(out) == 2):
        return out is not None
    result.fail(f"it should return the pair ({names}); got {type(out).__name__}")
    return False


def _compare(result: CheckResult, name: str, got: Any, expected: torch.Tensor) -> bool:
    """One output against the reference: type, shape, then values (where, and by how much)."""
    if not isinstance(got, torch.Tensor) or got.shape != expected.shape:
        result.fail(f"{name} has {_shape(got)}; expected a tensor of shape {tuple(expected.shape)}")
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


def _build(result: CheckResult, factory: Callable, *sizes: int, name: str = "factory") -> nn.Module | None:
    module = _call(result, f"{name}{sizes}", factory, *sizes)
    if module is None or isinstance(module, nn.Module):
        return module
    result.fail(f"{name}{sizes} returned a {type(module).__name__}", "return an nn.Module, so that it trains")
    return None


__all__ = ["CheckResult"]
