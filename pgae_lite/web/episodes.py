"""The episodes the live playground offers, and the choices its form shows (not in the paper).

Paper, Sec. 4: the 144 patterns (an action of one of the two cubes of an arrangement, at one speed),
36 of them held out for the test. The page is :func:`pgae_lite.robot.playground.play` in the
reader's browser, so it picks an episode as ``play`` does: the ``variation``-th recording of the
pattern (``arrangement``, ``action``) (:func:`~pgae_lite.robot.playground.scene_pattern`), or of the
pattern a typed description asks for in that arrangement (``pattern_for``). It holds
(:func:`page_rows`)::

    every test episode                          episodes.bin        fetched with the page's models
    the first recording of each training pattern episodes-train.bin  fetched when one is first chosen

each step as the model reads it, float32, [v_t (30); j_t (5)] normalised; and an index entry per
episode (:func:`episode_index`). :func:`play_choices` is what the form offers and the page computes
with, from the Python that decides it: the signals, arrangements and actions with their labels, the
targets and expected words of each signal, the robot's rate and NICO's torso.
"""
from __future__ import annotations

import inspect

import numpy as np
import torch

from pgae_lite.data.dataset import PGAEDataset
from pgae_lite.data.normaliser import Normaliser
from pgae_lite.robot.instructions import ROUTES
from pgae_lite.robot.play_result import EXPECTED, TARGETS
from pgae_lite.robot.playground import (
    ACTIONS,
    PLAY_SIGNALS,
    ROUTE_LABELS,
    ROUTE_SIGNAL,
    action_label,
    arrangement_label,
    play,
    scene_pattern,
)
from pgae_lite.sim.record import scene_layout
from pgae_lite.world.patterns import ACTION_SIDES, ARRANGEMENTS, Pattern, pattern_parts
from pgae_lite.world.words import SPEEDS, VOCABULARY

#: The page's episode files, by the split they hold.
FILES = {"test": "episodes.bin", "train": "episodes-train.bin"}


def page_rows(data: PGAEDataset) -> dict[str, list[int]]:
    """Rows of ``data`` the page holds, in the data's order: every test episode, and the first recording of
    each training pattern."""
    seen, train = set(), []
    for row in np.flatnonzero(~data.is_test).tolist():
        pattern = int(data.pattern[row])
        if pattern not in seen:
            seen.add(pattern)
            train.append(row)
    return {"test": np.flatnonzero(data.is_test).tolist(), "train": train}


def episode_index(data: PGAEDataset, rows: list[int], split: str, normaliser: Normaliser, config
                  ) -> tuple[np.ndarray, list[dict]]:
    """The episodes ``rows`` of ``data`` as one float32 array, and their index (offsets in floats, in it)."""
    part = data.subset(np.asarray(rows, dtype=int))
    tensors = normaliser.tensors(part)
    vision, joints = tensors["vision"], tensors["joints"]                     # (N, T, 30), (N, T, 5)
    chunks, index, at = [], [], 0
    for i in range(len(part)):
        n = int(part.lengths[i])
        action = torch.cat([vision[i, :n], joints[i, :n]], 1).numpy().astype(np.float32)   # (n, 35)
        pattern = int(part.pattern[i])
        p, (_, arrangement, _) = Pattern.from_number(pattern), pattern_parts(pattern)
        words = [VOCABULARY[w] for w in part.descriptions[i, 0] if w]            # its first description
        variation = int(str(part.ids[i]).rsplit("-", 1)[1])                  # "sim/PPP-V"
        layout = scene_layout(pattern, variation, config.base_seed, config.sim)   # where the cubes lay
        index.append({"id": str(part.ids[i]), "pattern": pattern, "split": split, "steps": n, "offset": at,
                      "arrangement": arrangement, "action": _action_of(pattern, arrangement),
                      "description": " ".join(words), "scene": [p.left, p.right],
                      "meaning": [p.action, p.colour, p.speed],
                      "cubes": [list(layout.left_xy), list(layout.right_xy)]})
        chunks.append(action.ravel())
        at += action.size
    return np.concatenate(chunks), index


def _action_of(pattern: int, arrangement: int) -> int:
    """The playground's action number (0-11) of ``pattern`` in its arrangement."""
    return next(k for k in range(len(ACTIONS)) if scene_pattern(arrangement, k) == pattern)


def play_choices(data: PGAEDataset, config) -> dict:
    """What the page's form offers and its ``run`` computes with (see the module docstring)."""
    from pgae_lite.sim.robot import JOINT_NAMES, TORSO

    (size, centre), top = TORSO, 0.0                                 # the torso's box, and the table top (z = 0)
    low, high = centre[2] - size[2] / 2, centre[2] + size[2] / 2
    above = [size[0], size[1], high - max(low, top)]                  # the part above the table top is drawn
    recorded = sorted({pattern_parts(int(p))[1] for p in data.pattern})
    return {"signals": list(PLAY_SIGNALS), "targets": TARGETS, "expected": EXPECTED, "routes": list(ROUTES),
            "default_signal": inspect.signature(play).parameters["signal"].default,      # play's
            "route_labels": ROUTE_LABELS, "route_signal": ROUTE_SIGNAL,
            "scenes": [list(a) for a in ARRANGEMENTS], "action_sides": [list(a) for a in ACTION_SIDES],
            "speeds": list(SPEEDS),                                       # pattern = 72 speed + 6 arrangement + k
            "arrangements": [{"number": a, "label": arrangement_label(a), "scene": list(ARRANGEMENTS[a])}
                             for a in recorded],
            "actions": [{"number": k, "label": action_label(k)} for k in range(len(ACTIONS))],
            "robot_rate": config.sim.physics_hz / config.sim.substeps,    # recorded steps per second
            "joint_range": data.joint_range(),                            # nRMSE's denominator
            "joint_names": [name.removeprefix("l_").replace("_", " ") for name in JOINT_NAMES],
            "torso": [[centre[0], centre[1], max(low, top) + above[2] / 2], above]}


__all__ = ["FILES", "episode_index", "page_rows", "play_choices"]
