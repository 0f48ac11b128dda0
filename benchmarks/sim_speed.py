"""Speed and reliability of the simulator: ms per frame, s per episode, first-try success.

    python benchmarks/sim_speed.py [--arrangements 0 3 6 9] [--variation 0] [--workers 1] [--profile book]

Records a sample of episodes (every one of the 12 actions on each chosen
arrangement, both views) with :func:`pgae_lite.sim.record_episode`, in the
simulator settings of the profile's dataset, and reports:

- ms per rendered frame (NICO's eye, mid-action; the backdrop-merge renderer
  and, for comparison, a full TinyRenderer pass over everything),
- seconds per episode (both views, including world building, planning, physics),
- the share of episodes whose first seed passed the checks, and the tracking error,
- the projected time for the 864-episode dataset with ``--workers`` processes
  (864 x s/episode / workers; measured with that many workers if > 1).

Writes results/sim_speed.json. Timings depend on what else runs on the
machine: the load average is recorded with them.
"""
from __future__ import annotations

import os
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict

import numpy as np

from harness import Benchmark
from pgae_lite.config import get_profile
from pgae_lite.world.patterns import Pattern, pattern_number
from pgae_lite.sim import SimConfig, Simulation, record_episode


def frame_times(config: SimConfig, n: int = 200) -> dict[str, float]:
    """Render NICO's view ``n`` times mid-action (pull right cube, slow): ms per frame."""
    sim = Simulation(config)
    sim.reset(4, 0, render=False)
    for q in sim.plan().joints[:45]:
        sim.step(q, render=False)
    scene = sim.scene
    scene.render()                                         # builds the backdrop
    out = {}
    for name, fn, reps in (("render_ms", scene.render, n), ("full_render_ms", scene.render_full, n // 4)):
        runs = []
        for _ in range(5):
            t = time.perf_counter()
            for _ in range(reps):
                fn()
            runs.append((time.perf_counter() - t) / reps * 1e3)
        out[name] = float(np.median(runs))
        out[name.replace("_ms", "_best_ms")] = float(min(runs))
    return out


def one(job: tuple[int, int, SimConfig]) -> dict:
    pattern, variation, config = job
    t = time.perf_counter()
    ep = record_episode(pattern, variation, config)
    return {"pattern": pattern, "seconds": time.perf_counter() - t, "attempts": ep.attempts,
            "frames": 2 * len(ep.joints), "tracking": ep.info["tracking_error"],
            "tracking_opposite": ep.info["tracking_error_opposite"]}


def main() -> None:
    bench = Benchmark("sim_speed", __doc__)
    bench.parser.add_argument("--arrangements", type=int, nargs="+", default=[0, 3, 6, 9])
    bench.parser.add_argument("--variation", type=int, default=0)
    bench.parser.add_argument("--workers", type=int, default=1)
    args = bench.parse()
    config = get_profile(args.profile).data.sim

    frames = frame_times(config)
    print(f"render: {frames['render_ms']:.2f} ms/frame (best {frames['render_best_ms']:.2f}); "
          f"full TinyRenderer pass: {frames['full_render_ms']:.2f} ms")

    jobs = [(pattern_number(s, a, i), args.variation, config)
            for a in args.arrangements for s in (0, 1) for i in range(6)]
    record_episode(*jobs[0])                               # warm up (imports, URDF file)
    t0 = time.perf_counter()
    if args.workers > 1:
        with ProcessPoolExecutor(args.workers) as pool:
            rows = list(pool.map(one, jobs))
    else:
        rows = [one(j) for j in jobs]
    wall = time.perf_counter() - t0
    seconds = np.array([r["seconds"] for r in rows])
    first_try = np.mean([r["attempts"] == 1 for r in rows])
    per_episode = wall / len(rows) * args.workers          # seconds of one worker per episode
    projected = 864 * wall / len(rows)                     # wall time for 864 episodes, these workers
    projected_2 = projected * args.workers / 2             # ... with 2 workers on 2 free cores
    failed = [Pattern.from_number(r["pattern"]).code for r in rows if r["attempts"] > 1]
    slow = seconds[[Pattern.from_number(r["pattern"]).speed == "slowly" for r in rows]]
    fast = seconds[[Pattern.from_number(r["pattern"]).speed == "fast" for r in rows]]
    print(f"{len(rows)} episodes (both views) in {wall:.1f} s with {args.workers} worker(s): "
          f"{per_episode:.3f} s/episode (slow {slow.mean():.3f} s, fast {fast.mean():.3f} s)")
    print(f"first-try success: {100 * first_try:.1f}%" + (f" (retried: {', '.join(failed)})" if failed else ""))
    print(f"max tracking error: NICO {max(r['tracking'] for r in rows):.3f} rad, "
          f"opposite {max(r['tracking_opposite'] for r in rows):.3f} rad")
    print(f"projected 864 episodes: {projected / 60:.1f} min with {args.workers} worker(s); "
          f"{projected_2 / 60:.1f} min with 2 workers on 2 cores")
    bench.write({"load_average": os.getloadavg(), "workers": args.workers, "arrangements": args.arrangements,
                 "variation": args.variation, "episodes": len(rows),
                 **frames, "seconds_per_episode": per_episode, "seconds_slow": float(slow.mean()),
                 "seconds_fast": float(fast.mean()), "first_try_success": float(first_try),
                 "max_tracking_error": max(max(r["tracking"], r["tracking_opposite"]) for r in rows),
                 "projected_minutes": projected / 60, "projected_minutes_2_workers": projected_2 / 60,
                 "config": asdict(config)})


if __name__ == "__main__":   # --workers N spawns processes, which re-import this file
    main()
