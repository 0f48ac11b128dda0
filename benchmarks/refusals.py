"""The robot says what it cannot do: how much of what it should refuse it refuses, and what it still executes.

    python benchmarks/refusals.py [--profile book] [--training PGAE-BERT-phrasings] [--per-class 120]

A set of sentences is generated from a small grammar of its own
(:mod:`pgae_lite.freeform.refusal_grammar`, written for this measure from general English, not from
the model's phrase lexicon), in five classes the robot
must refuse, each told in a scene of two cubes (a random arrangement):

- ``negation``: "don't push the red cube", "you must not drag the blue block", ...
- ``more_than_one``: two instructions, "push the red cube, then pull the blue one", ...
- ``absent_cube``: an instruction for a colour of the world that is not on the table;
- ``outside_colour``: a colour the world does not have ("the orange cube", "the black box");
- ``outside_action``: an action the robot cannot do ("lift", "rotate", "throw", ...);

and one class it must act on, ``valid``: one instruction for a cube on the table. Each sentence
is judged by :func:`pgae_lite.freeform.refusals.refusal` with the trained free-form model's encoder
and its readback of the sentence (``repeat language``, in an episode of the scene). Then the 108
held-out paraphrases (``pgae_lite/freeform/paraphrases.tsv``), as :func:`execute_paraphrases` tells
them to the 216 test episodes: how many are still executed (the refusal must not cost them).

Beside that grammar, typed variants (:mod:`pgae_lite.freeform.refusal_typed_grammar`, issue 62) in two sets
of templates kept apart: ``development`` (the rule was checked on it while written) and ``held-out``
(other templates, words and marks, never used to change the rule): text as a phone types it (other
apostrophes, spaces, zero-width and fullwidth characters), polite negations that still ask for one action,
words over several cubes, repetitions, opposite ways, and verbs the world lacks, read through the trained
model's own word lookup. For each set: the share refused among the sentences that must be refused, and
the share acted on among those that must be acted on.
Writes results/refusals.json: per class, the share refused, and examples of each outcome.
"""
from __future__ import annotations

import random

from harness import Benchmark

from pgae_lite.config import get_profile
from pgae_lite.freeform.paraphrases import load_paraphrases
from pgae_lite.freeform.refusal_grammar import CLASSES, sentence
from pgae_lite.freeform.refusal_typed_grammar import ACT, SETS, typed_sentence
from pgae_lite.freeform.refusal_typed_grammar import CLASSES as TYPED_CLASSES
from pgae_lite.freeform.refusals import refusal
from pgae_lite.robot.closedloop import variation_of
from pgae_lite.robot.instructions import paraphrase_of, say_back, scene_of
from pgae_lite.runs.data import simulated_dataset
from pgae_lite.runs.pipeline import trained_model
from pgae_lite.runs.rows import training_named
from pgae_lite.util.errors import ArgumentError
from pgae_lite.world.patterns import ARRANGEMENTS, pattern_parts


def main() -> None:
    bench = Benchmark("refusals", __doc__)
    bench.parser.add_argument("--training", default="PGAE-BERT-phrasings", help="the free-form model")
    bench.parser.add_argument("--per-class", type=int, default=120, help="sentences per class")
    args = bench.parse()
    try:
        training = training_named(args.training)
    except ArgumentError as e:
        bench.parser.error(str(e))
    profile = get_profile(args.profile)                      # resolved once, here
    data = simulated_dataset(profile, "cpu", progress=False)
    model = trained_model(training, profile, args.seeds[0], device="cpu", progress=False)
    encoder, test = model.model.language_encoder, data.split("test")
    rng = random.Random(args.seeds[0])

    arrangements = sorted({pattern_parts(int(p))[1] for p in test.pattern})
    rows_of = {a: [i for i, p in enumerate(test.pattern) if pattern_parts(int(p))[1] == a] for a in arrangements}
    told, rows = [], []                          # (set, class, text, arrangement), an episode of its scene
    for which, kinds, make in [("grammar", CLASSES, lambda k, scene: sentence(k, scene, rng))] + \
            [(w, TYPED_CLASSES, lambda k, scene, w=w: typed_sentence(k, scene, rng, w)) for w in SETS]:
        for kind in kinds:
            for _ in range(args.per_class):
                arrangement = rng.choice(arrangements)
                told.append((which, kind, make(kind, ARRANGEMENTS[arrangement]), arrangement))
                rows.append(rng.choice(rows_of[arrangement]))
    understood = say_back(model.model, test.subset(rows), model.normaliser, [t for _, _, t, _ in told])
    judged = {}
    for (which, kind, text, a), back in zip(told, understood):
        judged.setdefault(which, {}).setdefault(kind, []).append((text, back, refusal(text, encoder,
                                                                                      ARRANGEMENTS[a], back)))
    classes = {kind: _shares(judged["grammar"][kind]) for kind in CLASSES}
    typed = {}
    for which in SETS:
        shares = {kind: _shares(judged[which][kind]) for kind in TYPED_CLASSES}
        refuse = [j for k in TYPED_CLASSES if k not in ACT for j in judged[which][k]]
        act = [j for k in ACT for j in judged[which][k]]
        typed[which] = {"classes": shares,
                        "should_refuse_refused_%": round(100 * sum(bool(r) for *_, r in refuse) / len(refuse), 1),
                        "should_act_acted_on_%": round(100 * sum(not r for *_, r in act) / len(act), 1)}
    for which, table in [("grammar", classes)] + [(w, typed[w]["classes"]) for w in SETS]:
        print(which, {k: c["refused_%"] for k, c in table.items()}, flush=True)

    paraphrases = load_paraphrases()
    episodes = [paraphrase_of(int(p), variation_of(i), paraphrases) for p, i in zip(test.pattern, test.ids)]
    backs = say_back(model.model, test, model.normaliser, [p.text for p in episodes])
    refused = [(p.text, r) for p, pattern, back in zip(episodes, test.pattern, backs)
               if (r := refusal(p.text, encoder, scene_of(int(pattern)), back))]
    executed = len(episodes) - len(refused)
    for which in SETS:
        print(which, "refused of those to refuse:", typed[which]["should_refuse_refused_%"],
              "acted on of those to act on:", typed[which]["should_act_acted_on_%"], flush=True)
    bench.write({"training": args.training, "classes": classes, "typed": typed,
                 "should_refuse_%": round(100 * sum(c["refused"] for k, c in classes.items() if k != "valid")
                                          / sum(c["sentences"] for k, c in classes.items() if k != "valid"), 1),
                 "paraphrases": {"texts": len(paraphrases), "episodes": len(episodes), "executed": executed,
                                 "executed_%": round(100 * executed / len(episodes), 1),
                                 "refused_examples": [{"told": t, "said": r} for t, r in refused[:6]]}})
    print(bench.path)


def _shares(judged: list[tuple[str, str, str | None]]) -> dict:
    """One class's sentences judged (text, readback, refusal): the share refused and examples of each."""
    refused = [j for j in judged if j[2]]
    kept = [j for j in judged if not j[2]]
    return {"sentences": len(judged), "refused": len(refused), "refused_%": round(100 * len(refused) / len(judged), 1),
            "refused_examples": [{"told": t, "said": r} for t, _, r in refused[:4]],
            "acted_on_examples": [{"told": t, "understood": b} for t, b, _ in kept[:6]]}


if __name__ == "__main__":
    main()
