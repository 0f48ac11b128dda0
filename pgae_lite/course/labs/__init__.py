"""The course's labs: each changes one component of PGAE and shows the change's effect within a class period.

Not in the paper: a course built on it. Each lab is a module of this folder with the same names:
``TITLE``, what the lab changes, in a few words; ``STUDENT_NAME``, the name the lab's notebook gives the
student's component (e.g. ``MyBottleneck``); ``BASELINE``, the book's component, and ``REFERENCE``, the
lab's reference change (its solution); ``check(component)``, a
:class:`~pgae_lite.exercises.result.CheckResult` that judges a student's component by its structure and by
its behaviour, and says what is wrong; ``run(component, seed=0, profile=None)``, the student's run at the
lab's budget (what fits a class period), which trains with the component and returns the lab's figures,
``{name: number}``; ``FIGURES``, ``{name: label}`` of those figures; ``WRONG``, ``{mistake: (component,
words)}``, deliberately wrong components and words that the check's report on each must contain (CI grades
a notebook holding each: the lab's check must diagnose its mistakes).

- ``concat``         lab 1: the GMU replaced by concatenation, at the budget where the difference shows
- ``cae_widths``     lab 2: the CAE's channel widths
- ``opposite_task``  lab 3: a new task, describing what the opposite agent does
- ``gru``            lab 4: a GRU cell in place of the LSTM
- ``compare``        a lab's result beside its references over three seeds

``benchmarks/labs.py --lab NAME`` times ``run`` on ``BASELINE`` and ``REFERENCE`` over three seeds into
``results/lab-NAME.json``; the lab's notebook (``course/labs/``) sets the student's run beside those figures.
"""
from __future__ import annotations

import importlib
from types import ModuleType

from pgae_lite.util.errors import ArgumentError

#: the labs, in the order a course takes them (each a module of this folder)
LABS: tuple[str, ...] = ("concat", "cae_widths", "opposite_task", "gru")

_NAMES = ("TITLE", "STUDENT_NAME", "BASELINE", "REFERENCE", "check", "run", "FIGURES", "WRONG")


def lab(name: str) -> ModuleType:
    """The lab module called ``name`` (one of :data:`LABS`), checked to have every name a lab has."""
    if name not in LABS:
        raise ArgumentError(f"unknown lab {name!r}; the labs are: {', '.join(LABS)}")
    module = importlib.import_module(f"{__name__}.{name}")
    missing = [n for n in _NAMES if not hasattr(module, n)]
    if missing:
        raise ArgumentError(f"lab {name!r} lacks {', '.join(missing)}")
    return module
