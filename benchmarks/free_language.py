"""Free-form language: the paper's frozen PGAE-BERT against PGAE-BERT trained on phrasings.

    python benchmarks/free_language.py [--trainings PGAE-BERT PGAE-BERT-phrasings] [--seeds 0]
                                       [--profile book] [--threads 1] [--no-closed] [--workers 2]
    python benchmarks/free_language.py --original-data ../shared/pgae-original-data
                                       [--trainings PGAE-BERT-phrasings] [--seeds 0 1 2] [--workers 2]

Both models are trained (or loaded from the cache) on the profile's simulated
data: ``PGAE-BERT`` reads the dataset's descriptions only; ``PGAE-BERT-phrasings``
also reads generated sentences that say them in other words
(:mod:`pgae_lite.freeform.phrasing_bank`). Each of the 216 test episodes is told one of
the 108 held-out paraphrases of its instruction (``pgae_lite/freeform/paraphrases.tsv``,
never trained on), and measured three ways:

- *readback*: the paraphrase with ``repeat language``, no pictures of the action
  to help: is the generated description (action colour speed) the intended one?
- *execution*: the paraphrase with ``execute`` in the simulator, open loop (the
  decoder reads the recorded frames of the right action: it overstates
  understanding) and closed loop (its own camera); by two routes
  (:data:`pgae_lite.robot.instructions.ROUTES`): ``direct``, the paper's, the sentence's
  features into execute; ``said back`` (``said_back_*`` keys), the model's
  readback words executed;
- the canonical Table 1 cells of the model on the same data.

A variant trained on phrasings reads free text through its WordNet lookup
(:mod:`pgae_lite.freeform.word_lookup`); its readback is also measured without the
lookup (``*_no_lookup_%``), and ``looked_up`` lists the words it replaced.

The "unseen" subset holds the paraphrases with a word that occurs nowhere in the
model's training language (the descriptions, plus the phrasings' lexicon for the
variant). The full lexicon holds every word of the paraphrases, so that subset
is measured with ``PGAE-BERT-phrasings-held-out``, trained without the words of
:func:`pgae_lite.freeform.phrase_lexicon.held_out_words` (a rule on the lexicon alone).
Writes results/free_language.json.

With ``--original-data`` it measures only the canonical Table 1 of each training on
the authors' data (runs resumable under benchmarks/out/), into
results/free_language-original.json.

With ``--time`` it measures what the variant costs: ``PGAE-BERT`` and
``PGAE-BERT-phrasings`` trained from scratch, one after the other in this
process (same data, seed and load), each with an empty cache so that each pays
its own sentence encoding; into results/free_language-time.json.
"""
from __future__ import annotations

import os
import re
import tempfile
import time
from pathlib import Path

import numpy as np
import torch
from harness import Benchmark, side_by_side

from pgae_lite.bert.pretrained import input_text, load_transformer
from pgae_lite.config import Profile, get_profile
from pgae_lite.data.original import load_original
from pgae_lite.evaluate.table1 import evaluate, predict
from pgae_lite.freeform.paraphrases import load_paraphrases
from pgae_lite.freeform.phrase_lexicon import training_lexicon
from pgae_lite.robot.closedloop import variation_of
from pgae_lite.robot.instructions import ROUTES, execute_paraphrases, paraphrase_of
from pgae_lite.runs.data import simulated_dataset, trained_cae
from pgae_lite.runs.pipeline import trained_model, unit_profile
from pgae_lite.runs.rows import training_named
from pgae_lite.train.loop import train
from pgae_lite.util.storage import CACHE_ENV
from pgae_lite.world.words import SIGNALS, VOCABULARY


def words(text: str) -> set[str]:
    return set(re.findall(r"[a-z]+(?:-[a-z]+)*", text.lower()))


def training_words(training: str) -> set[str]:
    """Every word of the model's training language: signals, descriptions (and phrasings)."""
    seen = set().union(*(words(s) for s in SIGNALS), *(words(w) for w in VOCABULARY))
    phrasings = training_named(training).train.get("phrasings")
    if phrasings is not None:
        seen |= training_lexicon(phrasings.words).words()
    return seen


def original_run(training: str, seed: int, profile: Profile, path: str) -> dict:
    """One training's canonical Table 1 on the authors' data (resumable under benchmarks/out/)."""
    from pgae_lite.runs.pipeline import language_source

    torch.set_num_threads(1)
    data = load_original(path)
    prof = unit_profile(profile, training_named(training), seed, data)
    out = Path("benchmarks/out") / f"free_language-original-{profile.name}-{training}-s{seed}"
    trained = train(data, prof, out_dir=out, progress=False, name=training, language=language_source(prof))
    cells, _ = evaluate(trained.model, data, trained.normaliser)
    run = {"training": training, "seed": seed, "train_seconds": round(trained.seconds, 1),
           "table1": {s: {k: round(v, 4) for k, v in c.items()} for s, c in cells.items()}}
    print(run, flush=True)
    return run


def original_table1(bench: Benchmark, args, profile: Profile) -> None:
    """Each training's canonical Table 1 on the authors' data (e.g. for the variant, next to the paper's row)."""
    bench.name = "free_language-original"
    jobs = [(training, seed, profile, args.original_data)
            for training in args.trainings for seed in args.seeds]
    bench.write({"data": "authors'", "runs": side_by_side(original_run, jobs, args.workers)})


def training_time(bench: Benchmark, args, profile: Profile) -> None:
    """Training wall time of the variant against PGAE-BERT's, side by side in this one process."""
    bench.name = "free_language-time"
    from pgae_lite.runs.pipeline import language_source

    data = simulated_dataset(profile, "cpu", progress=False)
    load_transformer()                            # loaded once for both, outside the timings
    runs = []
    for seed in args.seeds:
        # the variant first: if the machine's load falls during the run, it favours PGAE-BERT
        for training in ("PGAE-BERT-phrasings", "PGAE-BERT"):
            prof = unit_profile(profile, training_named(training), seed, data)
            with tempfile.TemporaryDirectory() as empty:
                os.environ[CACHE_ENV] = empty     # nothing cached: the encoding is timed too
                t0 = time.perf_counter()
                train(data, prof, progress=False, name=training, language=language_source(prof))
                seconds = time.perf_counter() - t0
            runs.append({"training": training, "seed": seed, "seconds": round(seconds, 1),
                         "epochs": prof.train.epochs})
            print(runs[-1], flush=True)
    total = {t: sum(r["seconds"] for r in runs if r["training"] == t) for t in ("PGAE-BERT", "PGAE-BERT-phrasings")}
    bench.write({"runs": runs, "ratio": round(total["PGAE-BERT-phrasings"] / total["PGAE-BERT"], 2)})


def measure(training: str, seed: int, profile: Profile, closed: bool) -> dict:
    """One model's readback, execution (both routes) and Table 1 on the 216 test episodes."""
    torch.set_num_threads(1)                  # one core per worker: these networks gain nothing from two
    data = simulated_dataset(profile, "cpu", progress=False)
    cae, _ = trained_cae(profile, "cpu", progress=False)
    test = data.split("test")
    paraphrases = load_paraphrases()
    told = [paraphrase_of(int(p), variation_of(i), paraphrases) for p, i in zip(test.pattern, test.ids)]
    texts = [input_text("repeat language", t.text) for t in told]   # the readback's inputs
    seen = training_words(training)
    unseen = np.array([bool(words(t.text) - seen) for t in told])
    trained = trained_model(training_named(training), profile, seed, device="cpu", progress=False)
    model, norm = trained.model, trained.normaliser
    cells, _ = evaluate(model, data, norm)
    t0 = time.perf_counter()
    back = predict(model, test, norm, "repeat language", language=model.language_encoder.encode_texts(texts))
    run = {"training": training, "seed": seed, "episodes": len(told), "train_seconds": round(trained.seconds, 1),
           "table1": {s: {k: round(v, 4) for k, v in c.items()} for s, c in cells.items()},
           "readback_%": round(100 * back.correct.mean(), 2),
           "unseen_episodes": int(unseen.sum()),
           "readback_unseen_%": round(100 * back.correct[unseen].mean(), 2) if unseen.any() else None,
           "readback_wrong": [{"told": t.text, "understood": x}
                              for t, x, ok in zip(told, back.text, back.correct) if not ok][:40]}
    lookup = model.language_encoder.word_lookup
    if lookup is not None:    # the variant: what its WordNet lookup changed, and the readback without it
        run["looked_up"] = dict(sorted({w: p for t in told for w, p in lookup.replacements(t.text).items()}.items()))
        model.language_encoder.word_lookup = None
        plain = predict(model, test, norm, "repeat language", language=model.language_encoder.encode_texts(texts))
        model.language_encoder.word_lookup = lookup
        run["readback_no_lookup_%"] = round(100 * plain.correct.mean(), 2)
        if unseen.any():
            run["readback_unseen_no_lookup_%"] = round(100 * plain.correct[unseen].mean(), 2)
    for route in ROUTES:   # "direct": the paper's execute of the sentence; "said back": its readback's words
        table = execute_paraphrases(model, cae, norm, data, paraphrases, closed=closed, route=route,
                                    config=profile.data, progress=False)
        prefix = "" if route == "direct" else "said_back_"
        for loop in ("open", "closed"):
            if f"{loop}_passed" in table:
                passed = table[f"{loop}_passed"].to_numpy()
                run[f"{prefix}{loop}_success_%"] = round(100 * passed.mean(), 2)
                if unseen.any():
                    run[f"{prefix}{loop}_success_unseen_%"] = round(100 * passed[unseen].mean(), 2)
    run["measure_seconds"] = round(time.perf_counter() - t0, 1)
    print({k: v for k, v in run.items() if k not in ("readback_wrong", "table1", "looked_up")}, flush=True)
    return run


def main() -> None:
    bench = Benchmark("free_language", __doc__, seeds=[0])
    bench.parser.add_argument("--trainings", nargs="+", default=["PGAE-BERT", "PGAE-BERT-phrasings",
                                                                  "PGAE-BERT-phrasings-held-out"])
    bench.parser.add_argument("--no-closed", action="store_true", help="open loop only (fast)")
    bench.add_workers(1, "trainings")
    bench.add_original_data(None, "the authors' data: each training's canonical Table 1 there, and nothing else")
    bench.parser.add_argument("--time", action="store_true", help="the variant's training time against PGAE-BERT's")
    args = bench.parse()
    profile = get_profile(args.profile)                         # resolved once, here
    if args.original_data:
        return original_table1(bench, args, profile)
    if args.time:
        return training_time(bench, args, profile)
    simulated_dataset(profile, "cpu", progress=False)           # recorded once, before the workers start
    trained_cae(profile, "cpu", progress=False)
    jobs = [(training, seed, profile, not args.no_closed) for training in args.trainings for seed in args.seeds]
    runs = side_by_side(measure, jobs, args.workers)
    bench.write({"paraphrases": len(load_paraphrases()), "episodes": runs[0]["episodes"],
                 "routes": list(ROUTES), "runs": runs})


if __name__ == "__main__":   # recording the data spawns workers, which re-import this file
    main()
