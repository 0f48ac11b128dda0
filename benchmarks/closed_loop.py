"""Open vs closed loop in the simulator: does the robot do what it was told?

    python benchmarks/closed_loop.py [--trainings PGAE PGAE-BERT] [--seeds 0 1 2] [--profile book]
                                     [--limit 24] [--no-tracking] [--threads 1] [--workers 3]
                                     [--set plan_weight=1 epochs=200]

For each training and seed, the profile's recipe model on our simulated data
(:func:`pgae_lite.runs.pipeline.trained_model`: trained once, then cached) executes
each test episode twice (:func:`pgae_lite.robot.closedloop.compare`): open loop, the
paper's execute (the decoder reads the recorded vision), and closed loop (it
reads what its own motion shows). Prints the success rate per action and
speed and the time per episode; writes the success rates, their gap and every
failed closed-loop episode to results/closed_loop.json, with the model's Table 1
cells on the same data (:func:`pgae_lite.evaluate.table1.evaluate`) and whether its h says
which cube to move (:func:`pgae_lite.model.plan.which_cube_probe`; ``PGAE-no-plan`` is the
recipe without the plan head). ``--limit N`` takes N
episodes evenly spread over the 216 of the test split. The models are small:
one thread is as fast as two, so ``--workers N`` trains and runs N models side by
side, one process and one thread each. ``--set KEY=VALUE ...`` measures a candidate
recipe: those training options (:class:`pgae_lite.config.TrainConfig`) changed from
the profile's, for every training; the models are cached under their own names.
"""
from __future__ import annotations

import statistics
import time

import torch
from harness import Benchmark, key_value, side_by_side

from pgae_lite.config import Profile, get_profile
from pgae_lite.evaluate.table1 import evaluate
from pgae_lite.model.plan import which_cube_probe
from pgae_lite.robot.closedloop import compare, success_summary
from pgae_lite.runs.data import simulated_dataset, trained_cae
from pgae_lite.runs.pipeline import trained_model
from pgae_lite.runs.rows import training_named
from pgae_lite.util.errors import ArgumentError

_LOADED: dict = {}      # (data, CAE settings) -> (CAE, dataset), in this process


def cae_and_data(profile: Profile):
    """The profile's CAE and simulated data, loaded once per process (every job in a worker reads the same)."""
    key = (profile.data, profile.cae)
    if key not in _LOADED:
        _LOADED[key] = trained_cae(profile, "cpu", progress=False)[0], simulated_dataset(profile, "cpu", progress=False)
    return _LOADED[key]


def measure(training: str, seed: int, profile: Profile, threads: int | None, limit: int | None,
            tracking: bool, overrides: dict) -> dict:
    """One model (trained once, then cached) in open and closed loop, with its Table 1 cells."""
    if threads:
        torch.set_num_threads(threads)
    cae, data = cae_and_data(profile)
    trained = trained_model(training_named(training), get_profile(profile, **overrides), seed, device="cpu",
                            progress=False)
    t0 = time.perf_counter()
    table = compare(trained.model, cae, trained.normaliser, data, limit=limit,
                    config=profile.data, tracking=tracking)
    seconds = time.perf_counter() - t0
    summary = success_summary(table)
    open_, closed = 100 * table["open_passed"].mean(), 100 * table["closed_passed"].mean()
    print(f"\n== {training}, seed {seed}: open loop {open_:.1f}%, closed loop {closed:.1f}% "
          f"({len(table)} episodes, {seconds / len(table):.2f} s each)\n{summary.round(2).to_string()}",
          flush=True)
    failed = table[~table["closed_passed"]]
    cells, _ = evaluate(trained.model, data, trained.normaliser)
    return {"training": training, "seed": seed, "episodes": len(table),
            "open_success_%": round(open_, 2), "closed_success_%": round(closed, 2),
            "gap_points": round(open_ - closed, 2), "train_seconds": round(trained.seconds, 1),
            "seconds_per_episode": round(seconds / len(table), 3),
            "which_cube_probe_%": round(which_cube_probe(trained.model, data, trained.normaliser), 2),
            "table1": {s: {k: round(v, 4) for k, v in c.items()} for s, c in cells.items()},
            "summary": summary.reset_index().round(2).to_dict(orient="records"),
            "closed_failures": failed[["id", "description", "open_passed", "closed_reason"]]
            .to_dict(orient="records")}


def main() -> None:
    bench = Benchmark("closed_loop", __doc__, seeds=[0, 1, 2])
    bench.parser.add_argument("--trainings", nargs="+", default=["PGAE", "PGAE-BERT"])
    bench.parser.add_argument("--limit", type=int, default=None, help="this many test episodes, evenly spread")
    bench.parser.add_argument("--no-tracking", action="store_true",
                              help="send the model's joints to the motors as they are")
    bench.parser.add_argument("--set", nargs="+", type=key_value, default=[], metavar="KEY=VALUE",
                              help="training options changed from the recipe (a candidate recipe)")
    bench.add_workers(1, "trainings")
    args = bench.parse()
    overrides = dict(args.set)
    profile = get_profile(args.profile)                        # resolved once, here
    try:
        get_profile(profile, **overrides)                      # an unknown option fails here, at once
        for training in args.trainings:
            training_named(training)                           # so does an unknown training
    except ArgumentError as e:
        bench.parser.error(str(e))
    cae_and_data(profile)                                      # data and CAE made once, before the workers
    threads = 1 if args.workers > 1 else args.threads
    jobs = [(training, seed, profile, threads, args.limit, not args.no_tracking, overrides)
            for training in args.trainings for seed in args.seeds]
    runs = side_by_side(measure, jobs, args.workers)
    trainings = {}
    for training in args.trainings:            # over seeds: what the book quotes
        mine = [r for r in runs if r["training"] == training]
        trainings[training] = {
            "seeds": [r["seed"] for r in mine],
            "closed_median_%": statistics.median(r["closed_success_%"] for r in mine),
            "closed_min_%": min(r["closed_success_%"] for r in mine),
            "open_median_%": statistics.median(r["open_success_%"] for r in mine),
            "gap_max_points": max(r["gap_points"] for r in mine),
            "which_cube_probe_median_%": statistics.median(r["which_cube_probe_%"] for r in mine),
            # of the failed closed-loop episodes, those in which the other cube moved (the wrong cube)
            "other_cube_%_of_failures": round(100 * sum("the other cube moved" in f["closed_reason"]
                                                        for r in mine for f in r["closed_failures"])
                                              / max(1, sum(len(r["closed_failures"]) for r in mine)), 2),
            "describe_median_%": statistics.median(r["table1"]["describe"]["accuracy"] for r in mine)}
        print(f"{training}: closed loop median {trainings[training]['closed_median_%']:.2f}%, "
              f"worst seed {trainings[training]['closed_min_%']:.2f}%")
    bench.write({"limit": args.limit, "tracking": not args.no_tracking, "overrides": overrides,
                 "trainings": trainings, "runs": runs})


if __name__ == "__main__":   # recording the data spawns workers, which re-import this file
    main()
