"""How much do the six recordings of a pattern differ? A floor under any model's joint error.

    python experiments/variation_floor.py [--every 7] [--set timing_jitter=0.15 ...]

A model that executes "push red slowly" gets the description and the first
step; it cannot know the parts of a recording's random variation that the
first step does not show (when each phase starts, how far the cube goes).
Predicting the mean trajectory of a pattern's six recordings is then the best
it can do without looking at later frames, and its error is the spread of the
six around their mean. This script measures that spread on the *planned*
joints (inverse kinematics only, no physics or rendering: a second per
setting) as nRMSE in % of the joints' range (4.04 rad on the book data), for
the default :class:`~pgae_lite.sim.SimConfig` and with single jitters turned
off, so one can see which jitter costs what.

Appends one JSON line per run to experiments/out/variation_floor.jsonl.
"""
from __future__ import annotations

import argparse
import dataclasses
import json
from pathlib import Path

import numpy as np

from pgae_lite.sim import SimConfig
from pgae_lite.sim.record import episode_seed, shared_simulation

OUT = Path(__file__).resolve().parent / "out" / "variation_floor.jsonl"
JOINT_RANGE = 4.038   # observed range of the book dataset's joints (rad), as evaluate.nrmse divides by


def spread(config: SimConfig, patterns: range, variations: int = 6) -> float:
    """nRMSE (%) of each pattern's planned trajectories around their mean, steps 1..T."""
    sim = shared_simulation(config)
    squares, count = 0.0, 0
    for pattern in patterns:
        plans = []
        for variation in range(variations):
            sim.reset(pattern, variation, 0, "nico", render=False)
            rng = np.random.default_rng([episode_seed(pattern, variation), 1])   # the recordings' first draw
            plans.append(sim.plan(rng).joints)
        joints = np.array(plans)                                  # (variations, T, 5)
        deviation = joints - joints.mean(0, keepdims=True)
        squares += float((deviation[:, 1:] ** 2).sum())           # step 0 is given to the model
        count += deviation[:, 1:].size
    return 100 * np.sqrt(squares / count) / JOINT_RANGE


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--every", type=int, default=7, help="use every N-th pattern (default 7: 21 patterns)")
    parser.add_argument("--set", nargs="*", default=[], metavar="FIELD=VALUE",
                        help="change SimConfig fields first, e.g. timing_jitter=0.15 cube_jitter=0.01")
    args = parser.parse_args()
    changes = {}
    for item in args.set:
        name, value = item.split("=", 1)
        changes[name] = tuple(float(v) for v in value.split(",")) if "," in value else float(value)
    base = dataclasses.replace(SimConfig(), **changes)
    patterns = range(0, 144, args.every)
    settings = {"as configured": {}, "no timing jitter": {"timing_jitter": 0.0},
                "fixed travel": {"distance": (sum(base.distance) / 2,) * 2},
                "no contact jitter": {"lateral_jitter": 0.0, "height_jitter": 0.0},
                "no cube jitter": {"cube_jitter": 0.0}}
    rows = {}
    for label, change in settings.items():
        rows[label] = round(spread(dataclasses.replace(base, **change), patterns), 3)
        print(f"{label:20s} {rows[label]:.3f} % nRMSE")
    OUT.parent.mkdir(parents=True, exist_ok=True)
    with OUT.open("a") as f:
        f.write(json.dumps({"config": {k: v for k, v in dataclasses.asdict(base).items()
                                       if "jitter" in k or k == "distance"},
                            "patterns": len(patterns), "spread_nrmse": rows}) + "\n")


if __name__ == "__main__":
    main()
