"""What each mechanism of the free-form variant adds, on the same held-out sentences and seeds.

    python benchmarks/free_form_ablation.py [--seeds 0 1 2] [--workers 2] [--threads 1] [--profile book]

The paper's PGAE-BERT reads any text but was trained on the dataset's descriptions
alone. The book's free-form variant (``PGAE-BERT-phrasings``; appendix A4) adds five
mechanisms; each row here adds one to the row before it:

1. ``PGAE-BERT``: the paper's model (frozen transformer, mean pooling);
2. ``+ phrasings``: also trained on 60 generated phrasings of every instruction under
   repeat language (the transformer frozen, mean pooling);
3. ``+ attention pooling``: a trained attention pooling in place of the mean;
4. ``+ tuned top layer``: the transformer's top layer tuned on the phrasings;
5. ``+ word lookup``: the same model, words never trained on looked up in WordNet first;

and each row's execution by both *routes*: ``direct`` (the paper's: the sentence's features
into execute) and ``said back`` (the model's readback words executed). Rows 2 to 5 train
without the held-out words (:func:`pgae_lite.freeform.phrase_lexicon.held_out_words`), so that
"unseen" is the same subset of sentences for every row: the paraphrases with a word that
occurs nowhere in those rows' training language. Rows 1 to 4 are measured without the lookup.

Each of the 216 test episodes is told one of the 108 held-out paraphrases of its instruction
(never trained on). Readback: the paraphrase under repeat language, no pictures of the action:
is the generated description the intended one? Execution: the paraphrase under execute in the
simulator, open loop, judged by the simulator (did the named cube move the named way?); an
instruction the robot refuses (:mod:`pgae_lite.freeform.refusals`) is not executed and counts as not done.
Writes results/free_form_ablation.json.
"""
from __future__ import annotations

import time

import numpy as np
import torch
from free_language import training_words, words
from harness import Benchmark, side_by_side

from pgae_lite.bert.config import PretrainedConfig
from pgae_lite.bert.pretrained import input_text
from pgae_lite.config import Profile, get_profile
from pgae_lite.evaluate.table1 import predict
from pgae_lite.freeform.attention_pooling import AttentionConfig
from pgae_lite.freeform.paraphrases import load_paraphrases
from pgae_lite.robot.closedloop import variation_of
from pgae_lite.robot.instructions import ROUTES, execute_paraphrases, paraphrase_of
from pgae_lite.runs.data import simulated_dataset, trained_cae
from pgae_lite.runs.pipeline import trained_model
from pgae_lite.runs.rows import TRAININGS, Training

PHRASINGS_HELD_OUT = TRAININGS["PGAE-BERT-phrasings-held-out"]
_HELD_OUT = PHRASINGS_HELD_OUT.train
#: row name -> the training it measures (rows 1 to 4; row 5 is row 4 with its lookup)
ROWS: dict[str, Training] = {
    "PGAE-BERT": TRAININGS["PGAE-BERT"],
    "+ phrasings": Training("PGAE-BERT-phrasings-mean-held-out", model={"language": PretrainedConfig()},
                            train=_HELD_OUT),
    "+ attention pooling": Training("PGAE-BERT-phrasings-attention-held-out",
                                    model={"language": AttentionConfig()}, train=_HELD_OUT),
    "+ tuned top layer": PHRASINGS_HELD_OUT,
}
LOOKUP_ROW = "+ word lookup"


def measure_as_is(model, data, norm, cae, profile: Profile, paraphrases, told, unseen) -> dict:
    """Readback and open-loop execution by both routes, with the model's encoder as it is now."""
    test = data.split("test")
    texts = [input_text("repeat language", t.text) for t in told]
    back = predict(model, test, norm, "repeat language", language=model.language_encoder.encode_texts(texts))
    cells = {"readback_%": round(100 * float(back.correct.mean()), 2),
             "readback_unseen_%": round(100 * float(back.correct[unseen].mean()), 2)}
    for route in ROUTES:
        table = execute_paraphrases(model, cae, norm, data, paraphrases, closed=False, route=route,
                                    config=profile.data, progress=False)
        # a refused instruction is not executed: it counts as not done
        passed = table["open_passed"].fillna(False).to_numpy(dtype=bool)
        key = route.replace(" ", "_")
        cells[f"{key}_refused"] = int((table["refused"] != "").sum())
        cells[f"{key}_open_success_%"] = round(100 * float(passed.mean()), 2)
        cells[f"{key}_open_success_unseen_%"] = round(100 * float(passed[unseen].mean()), 2)
    return cells


def run(row: str, seed: int, profile: Profile) -> list[dict]:
    """One training's row (and, for the tuned variant, the lookup's row after it)."""
    torch.set_num_threads(1)                  # one core per worker
    data = simulated_dataset(profile, "cpu", progress=False)
    cae, _ = trained_cae(profile, "cpu", progress=False)
    test = data.split("test")
    paraphrases = load_paraphrases()
    told = [paraphrase_of(int(p), variation_of(i), paraphrases) for p, i in zip(test.pattern, test.ids)]
    seen = training_words(PHRASINGS_HELD_OUT.name)         # one "unseen" subset for every row
    unseen = np.array([bool(words(t.text) - seen) for t in told])
    trained = trained_model(ROWS[row], profile, seed, device="cpu", progress=False)
    model, norm = trained.model, trained.normaliser
    t0 = time.perf_counter()
    encoder = model.language_encoder
    lookup = encoder.word_lookup
    if lookup is not None:                    # rows 1 to 4: no lookup
        encoder.word_lookup = None
    rows = [{"row": row, "training": ROWS[row].name, "seed": seed, "train_seconds": round(trained.seconds, 1),
             **measure_as_is(model, data, norm, cae, profile, paraphrases, told, unseen)}]
    if row == "+ tuned top layer":
        encoder.word_lookup = lookup
        rows.append({"row": LOOKUP_ROW, "training": ROWS[row].name, "seed": seed,
                     "train_seconds": round(trained.seconds, 1),
                     **measure_as_is(model, data, norm, cae, profile, paraphrases, told, unseen)})
    for r in rows:
        r["episodes"], r["unseen_episodes"] = len(told), int(unseen.sum())
        r["measure_seconds"] = round(time.perf_counter() - t0, 1)
        print(r, flush=True)
    return rows


def main() -> None:
    bench = Benchmark("free_form_ablation", __doc__, seeds=[0, 1, 2])
    bench.add_workers(2, "trainings")
    args = bench.parse()
    profile = get_profile(args.profile)                         # resolved once, here
    simulated_dataset(profile, "cpu", progress=False)           # recorded once, before the workers start
    trained_cae(profile, "cpu", progress=False)
    jobs = [(row, seed, profile) for row in ROWS for seed in args.seeds]
    runs = [r for rows in side_by_side(run, jobs, args.workers) for r in rows]
    bench.write({"rows": [*ROWS, LOOKUP_ROW], "paraphrases": len(load_paraphrases()), "runs": runs})


if __name__ == "__main__":   # spawned workers re-import this file
    main()
