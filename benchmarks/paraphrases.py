"""Free-form instructions in the simulator: does PGAE-BERT do what a paraphrase asks?

    python benchmarks/paraphrases.py [CHECKPOINT] [--seeds 0] [--profile book] [--limit 36] [--open-only]
                                     [--threads 1] [--out results/paraphrases.json]

The paper (Sec. 3 and 5) says PGAE-BERT "has the potential to recognise unseen
natural language". Here every test episode is told one of the 108 held-out
paraphrases of its own instruction (``pgae_lite/paraphrases.tsv``, e.g. "Could
you shove the crimson cube forward in a hurry"; episode variation v gets the
paraphrase v mod 3 of its meaning, so each is used twice over the 216 episodes)
and executes it (:func:`pgae_lite.robot.instructions.execute_paraphrases`): open loop,
the paper's execute (the decoder reads the recorded vision), and closed loop
(it reads what its own motion shows). Success is the simulator's check that
the named cube moved the named way; nRMSE is against the recorded joints of the
episode, the intended action.

CHECKPOINT is a PGAE-BERT checkpoint trained on the profile's simulated data;
without it, each seed's cached ``trained_pgae("PGAE-BERT", profile, seed)`` is
used, and trained first if it is not cached (about 10 minutes on a 2-core CPU
in the ``book`` profile). ``--limit N`` takes N test episodes evenly spread.
Prints the success rate per action and speed and the time per episode; writes
them, and every failed episode of the loop measured last, to
results/paraphrases.json. The models are small: one thread is as fast as two.
"""
from __future__ import annotations

import time

from harness import Benchmark
from pgae_lite.robot.closedloop import success_summary
from pgae_lite.config import get_profile
from pgae_lite.robot.instructions import execute_paraphrases
from pgae_lite.world.words import LanguageError
from pgae_lite.runs.pipeline import simulated_dataset, trained_cae, trained_pgae
from pgae_lite.train.checkpoint import load_model


def main() -> None:
    bench = Benchmark("paraphrases", __doc__)
    bench.parser.add_argument("checkpoint", nargs="?",
                              help="a PGAE-BERT checkpoint (default: the profile's cached model of each seed)")
    bench.parser.add_argument("--limit", type=int, default=None, help="this many test episodes, evenly spread")
    bench.parser.add_argument("--open-only", action="store_true", help="only the paper's open-loop execute (fast)")
    args = bench.parse()

    data = simulated_dataset(args.profile, "cpu", progress=False)
    cae, _ = trained_cae(args.profile, "cpu", progress=False)
    if args.checkpoint:                # one model, no seeds
        model, normaliser, ckpt = load_model(args.checkpoint, "cpu", data)
        models = [(args.checkpoint, None, model, normaliser, ckpt["profile"]["model"])]
    else:
        models = []
        for seed in args.seeds:
            trained = trained_pgae("PGAE-BERT", args.profile, seed, device="cpu", progress=False)
            models.append((f"trained_pgae('PGAE-BERT', {args.profile!r}, seed={seed})", seed, trained.model,
                           trained.normaliser, trained.profile.to_dict()["model"]))

    loop = "open" if args.open_only else "closed"                  # the loop whose failures are kept
    failure_columns = ["id", "meaning", "description", *(["open_passed"] if loop == "closed" else []), f"{loop}_reason"]
    runs = []
    for name, seed, model, normaliser, model_config in models:
        t0 = time.perf_counter()
        try:
            table = execute_paraphrases(model, cae, normaliser, data, limit=args.limit, closed=not args.open_only,
                                        config=get_profile(args.profile).data)
        except LanguageError as e:     # a PGAE checkpoint (LSTM language encoder): it cannot read them
            raise SystemExit(f"error: {e}") from None
        seconds = time.perf_counter() - t0
        summary = success_summary(table)
        success = {k: round(100 * table[f"{k}_passed"].mean(), 2) for k in ("open", "closed") if f"{k}_passed" in table}
        print(f"\n== {name}: " + ", ".join(f"{k} loop {v:.1f}%" for k, v in success.items())
              + f" ({len(table)} episodes, {seconds / len(table):.2f} s each)")
        print(summary.round(2).to_string())
        failed = table[~table[f"{loop}_passed"]]
        if len(failed):
            print(f"{loop}-loop failures: {len(failed)} (the first 10; all of them in the result file)")
            print(failed[["id", "meaning", "description", f"{loop}_reason"]].head(10).to_string(index=False))
        runs.append({"model": name, "seed": seed, "model_config": model_config, "episodes": len(table),
                     **{f"{k}_success_%": v for k, v in success.items()},
                     "seconds_per_episode": round(seconds / len(table), 3),
                     "summary": summary.reset_index().round(2).to_dict(orient="records"),
                     f"{loop}_failures": failed[failure_columns].to_dict(orient="records")})
    # with CHECKPOINT no seed was run: the result file says seeds null, not --seeds' default
    bench.write({"limit": args.limit, "closed": not args.open_only, "runs": runs},
                **({"seeds": None} if args.checkpoint else {}))


if __name__ == "__main__":   # recording the data spawns workers, which re-import this file
    main()
