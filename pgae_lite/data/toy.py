"""A small synthetic dataset with the structure of the paper's (for tests and quick demos).

Not the paper's data and not a physics simulation: joint trajectories are
smooth minimum-jerk curves whose direction depends on the action and the
cube, and the 30 "visual features" are a fixed random projection of where
the two coloured cubes and the hand are. It has the paper's 144 patterns,
its split, its 8 descriptions per action and its shapes (lengths 100 and 50
padded to 100), so every part of PGAE can be run and tested on a fresh
machine in seconds. The simulator chapters make realistic data.
"""
from __future__ import annotations

import numpy as np

from pgae_lite.data.dataset import PGAEDataset, from_recordings
from pgae_lite.world.patterns import Pattern
from pgae_lite.world.words import COLOURS


def _min_jerk(tau: np.ndarray) -> np.ndarray:
    """s(τ) = 10τ³ − 15τ⁴ + 6τ⁵: a smooth 0 → 1 ramp."""
    return 10 * tau**3 - 15 * tau**4 + 6 * tau**5


def toy_dataset(variations: int = 6, seed: int = 0, patterns: range | list[int] = range(144)) -> PGAEDataset:
    """``variations`` recordings of each pattern, with small seeded random variations."""
    rng = np.random.default_rng(seed)
    world = np.random.default_rng(1234)                      # the fixed "camera" and "arm", same for every seed
    camera = world.normal(0, 0.6, (30, 2 * len(COLOURS) + 6))
    opposite_camera = world.normal(0, 0.6, (30, 2 * len(COLOURS) + 6))
    reach = {"L": np.array([0.25, 0.1, -0.1, 0.2, 0.0]), "R": np.array([-0.05, 0.15, 0.1, 0.25, 0.05])}
    motion = {"push": np.array([0.1, 0.2, 0.0, -0.15, 0.0]), "pull": np.array([-0.1, -0.2, 0.0, 0.15, 0.0]),
              "slide": np.array([0.0, 0.05, 0.2, 0.0, 0.1])}
    cube_motion = {"push": np.array([0.0, 0.1]), "pull": np.array([0.0, -0.1]), "slide": np.array([0.1, 0.0])}
    recordings = []
    for v in range(variations):
        for number in patterns:
            p = Pattern.from_number(number)
            n = p.steps
            tau = np.linspace(0, 1, n)[:, None]
            start = np.array([0.5, 0.6, 0.5, 0.3, 0.5]) + rng.normal(0, 0.01, 5)
            go = _min_jerk(np.clip(2 * tau, 0, 1))           # reach the cube in the first half
            act = _min_jerk(np.clip(2 * tau - 1, 0, 1))      # then move it
            joints = start + go * reach[p.side] * (1 + rng.normal(0, 0.03)) + act * motion[p.action]
            cubes = {"L": np.array([-0.3, 0.0]) + rng.normal(0, 0.01, 2),
                     "R": np.array([0.3, 0.0]) + rng.normal(0, 0.01, 2)}
            cube_path = cubes[p.side] + act * cube_motion[p.action]      # (n, 2)
            other = np.broadcast_to(cubes["R" if p.side == "L" else "L"], (n, 2))
            left_pos, right_pos = (cube_path, other) if p.side == "L" else (other, cube_path)
            colour = np.zeros((n, 2 * len(COLOURS)))
            colour[:, COLOURS.index(p.left)] = 1
            colour[:, len(COLOURS) + COLOURS.index(p.right)] = 1
            hand = joints[:, :2]
            scene = np.concatenate([colour, left_pos, right_pos, hand], 1)            # (n, 18)
            mirrored = np.concatenate([colour[:, ::-1], -right_pos, -left_pos, -hand], 1)
            vision = 1 / (1 + np.exp(-(scene @ camera.T))) + rng.normal(0, 0.01, (n, 30))
            opposite = 1 / (1 + np.exp(-(mirrored @ opposite_camera.T))) + rng.normal(0, 0.01, (n, 30))
            recordings.append((p, f"toy{v}/pattern{number:03d}", joints, vision, opposite))
    return from_recordings(recordings, source=f"toy:seed={seed}")
