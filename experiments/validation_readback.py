"""Validation readback: free-form language measured without touching the test paraphrases.

    python experiments/validation_readback.py PGAE-BERT:0 PGAE-BERT-phrasings:0 [--seed 4242] [--closed]
    python experiments/validation_readback.py PGAE-BERT-phrasings:0:input_noise=0.05
    python experiments/validation_readback.py PGAE-BERT-phrasings:1:phrasings.prob=0.5
    python experiments/validation_readback.py PGAE-BERT-phrasings-held-out:0 --grammar second [--no-lookup]

Each of the 216 test episodes is told, with ``repeat language``, one of 12
sentences of its meaning that the phrasing grammar (:mod:`pgae_lite.freeform.phrasings`)
generates with another seed than any training uses; the model's description
must name the intended action, colour and speed. With ``--grammar second``
the 12 sentences come from :mod:`second_grammar` instead (other sentence
forms, the same lexicon): a check that does not share the training grammar.
This is the validation set a free-form variant is chosen on;
``pgae_lite/freeform/paraphrases.tsv`` stays the test set (``benchmarks/free_language.py``).
The "held-out words" subset holds the sentences with a word of
:func:`pgae_lite.freeform.phrase_lexicon.held_out_words`.
Models are trained with the book profile, or loaded from the cache; ``name=value``
after the seed changes one training option that the training itself does not set (a number,
or names joined by ``+``), and ``part.field=value`` one field of a part the training sets (e.g.
``phrasings.prob``, :class:`pgae_lite.freeform.phrasing_bank.PhrasingsConfig`).
With ``--closed`` each episode is also told its sentence with ``execute`` and
run in the simulator's closed loop (:func:`pgae_lite.robot.instructions.execute_paraphrases`,
``--routes direct "said back"``), and the failures are counted by the simulator's reason.
"""
import argparse
from dataclasses import fields, replace

import numpy as np
import torch
from second_grammar import second_phrasings

from pgae_lite.bert.pretrained import input_text
from pgae_lite.config import get_profile
from pgae_lite.evaluate.table1 import predict
from pgae_lite.freeform.paraphrases import Paraphrase
from pgae_lite.freeform.phrase_lexicon import held_out_words, words_of
from pgae_lite.freeform.phrasings import phrasings
from pgae_lite.robot.instructions import ROUTES, execute_paraphrases
from pgae_lite.runs.data import simulated_dataset, trained_cae
from pgae_lite.runs.pipeline import trained_model
from pgae_lite.runs.rows import Training, training_named
from pgae_lite.train.config import TrainConfig
from pgae_lite.util.errors import ArgumentError
from pgae_lite.world.patterns import Pattern
from pgae_lite.world.words import LanguageError, parse_description


def parse(text: str) -> tuple[str, ...] | None:
    """A description's canonical (action, colour, speed), None for any other text."""
    try:
        return parse_description(text)
    except LanguageError:
        return None


def option_value(default, text: str):
    """An option's value from the command line, as its ``default`` is: names joined by '+' for a tuple, a text
    for a text, else a number."""
    if isinstance(default, tuple):
        return tuple(text.split("+"))
    if isinstance(default, str):
        return text
    return int(text) if text.isdigit() else float(text)


def with_options(spec: str, training: Training, options: dict[str, str]) -> tuple[Training, dict]:
    """``training`` with the fields of its parts that ``options`` name (``part.field``) changed, and the plain
    training options of ``options`` (for the profile); a bad option is a command-line error."""
    plain, parts = {}, {}
    for name, text in options.items():
        part, _, field = name.partition(".")
        if field:
            current = training.train.get(part)
            if current is None or field not in {f.name for f in fields(current)}:
                parser.error(f"{spec}: the training {training.name} sets no part {part!r} with a field {field!r} "
                             f"({training.train})")
            parts.setdefault(part, {})[field] = option_value(getattr(current, field), text)
        elif name in training.train:             # the training would overwrite it
            parser.error(f"{spec}: {name} is set by the training {training.name} itself "
                         f"({training.train}); change it in pgae_lite.runs.rows instead")
        elif not hasattr(TrainConfig(), name):
            parser.error(f"{spec}: unknown training option {name!r}")
        else:
            plain[name] = option_value(getattr(TrainConfig(), name), text)
    changed = {part: replace(training.train[part], **changes) for part, changes in parts.items()}
    return replace(training, train={**training.train, **changed}), plain


# the simulator's reasons for a failed episode, by kind (one failure may have several)
REASONS = {"sideways": "sideways", "too little along": "along the direction", "other cube": "other cube"}

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("models", nargs="+", help="TRAINING:SEED[:OPTION=VALUE], e.g. PGAE-BERT-phrasings:0, "
                    "PGAE-BERT-phrasings:1:phrasings.prob=0.5")
parser.add_argument("--seed", type=int, default=4242, help="the phrasing grammar's seed (not a training one)")
parser.add_argument("--grammar", choices=("training", "second"), default="training",
                    help="the training grammar with another seed, or experiments/second_grammar.py's forms")
parser.add_argument("--no-lookup", action="store_true",
                    help="read free text without the variant's WordNet lookup (pgae_lite/freeform/word_lookup.py)")
parser.add_argument("--closed", action="store_true", help="also execute the sentences in the closed loop")
parser.add_argument("--routes", nargs="+", default=["direct"], choices=ROUTES,
                    help="how the closed loop reads the sentence (pgae_lite.robot.instructions.ROUTES)")
args = parser.parse_args()
PROFILE = get_profile("book")      # resolved once, here
models = {}                # spec -> (training, seed, plain options), each checked before anything loads
for spec in args.models:
    name, seed, *options = spec.split(":")
    try:
        training = training_named(name)
    except ArgumentError as e:
        parser.error(f"{spec}: {e}")
    models[spec] = *with_options(spec, training, dict(option.split("=", 1) for option in options)), int(seed)
    get_profile(PROFILE, **models[spec][1])       # an option of the wrong kind fails here, at once
torch.set_num_threads(1)

data = simulated_dataset(PROFILE, progress=False)
test = data.split("test")
held = set(held_out_words())
sentences = {}
texts, unseen = [], []
for i, number in enumerate(test.pattern):
    pattern = Pattern.from_number(int(number))
    meaning = (pattern.action, pattern.colour, pattern.speed)
    if meaning not in sentences:
        sentences[meaning] = (phrasings if args.grammar == "training" else second_phrasings)(
            *meaning, 12, seed=args.seed)
    text = sentences[meaning][i % 12]
    texts.append(input_text("repeat language", text))
    unseen.append(bool(set(words_of(text)) & held))
unseen = np.array(unseen)

for spec, (training, options, seed) in models.items():
    trained = trained_model(training, get_profile(PROFILE, **options), seed, device="cpu", progress=False)
    if args.no_lookup:
        trained.model.language_encoder.word_lookup = None
    heard = trained.model.language_encoder.encode_texts(texts)
    back = predict(trained.model, test, trained.normaliser, "repeat language", language=heard)
    print(f"{spec}: validation readback {100 * back.correct.mean():.2f}% "
          f"(held-out words {100 * back.correct[unseen].mean():.2f}% of {unseen.sum()}, "
          f"others {100 * back.correct[~unseen].mean():.2f}%)", flush=True)
    if args.closed:   # 3 sentences per meaning, each told to the 2 episodes paraphrase_of gives it
        said = [Paraphrase(t, *m) for m, ts in sentences.items() for t in ts[:3]]
        cae, _ = trained_cae(PROFILE, "cpu", progress=False)
        for route in args.routes:
            table = execute_paraphrases(trained.model, cae, trained.normaliser, data, said, route=route,
                                        config=PROFILE.data, progress=False)
            reasons = table[~table.closed_passed].closed_reason
            meant = [tuple(m.split()) for m in table.meaning]
            right = np.mean([m == parse(a) for m, a in zip(meant, table.acted_on)])
            kinds = {kind: int(reasons.str.contains(pattern).sum()) for kind, pattern in REASONS.items()}
            print(f"{spec}: validation closed loop ({route}) {100 * table.closed_passed.mean():.2f}% of "
                  f"{len(table)} (acted on the intended meaning: {100 * right:.2f}%); {len(reasons)} failures, "
                  f"of which {kinds}", flush=True)
