"""Validation readback: free-form language measured without touching the test paraphrases.

    python experiments/validation_readback.py PGAE-BERT:0 PGAE-BERT-phrasings:0 [--seed 4242]

Each of the 216 test episodes is told, with ``repeat language``, one of 12
sentences of its meaning that the phrasing grammar (:mod:`pgae_lite.phrasings`)
generates with another seed than any training uses; the model's description
must name the intended action, colour and speed. This is the validation set a
free-form variant is chosen on; ``pgae_lite/paraphrases.tsv`` stays the test
set (``benchmarks/free_language.py``). The "held-out words" subset holds the
sentences with a word of :func:`pgae_lite.phrase_lexicon.held_out_words`.
Models are trained with the book profile, or loaded from the cache.
"""
import argparse

import numpy as np
import torch

from pgae_lite.evaluate import predict
from pgae_lite.patterns import Pattern
from pgae_lite.phrase_lexicon import held_out_words, words_of
from pgae_lite.phrasings import phrasings
from pgae_lite.pipeline import simulated_dataset, trained_pgae
from pgae_lite.pretrained import input_text

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("models", nargs="+", help="TRAINING:SEED, e.g. PGAE-BERT-phrasings:0")
parser.add_argument("--seed", type=int, default=4242, help="the phrasing grammar's seed (not a training one)")
args = parser.parse_args()
torch.set_num_threads(1)

test = simulated_dataset("book", progress=False).split("test")
held = set(held_out_words())
sentences = {}
texts, unseen = [], []
for i, number in enumerate(test.pattern):
    pattern = Pattern.from_number(int(number))
    meaning = (pattern.action, pattern.colour, pattern.speed)
    if meaning not in sentences:
        sentences[meaning] = phrasings(*meaning, 12, seed=args.seed)
    text = sentences[meaning][i % 12]
    texts.append(input_text("repeat language", text))
    unseen.append(bool(set(words_of(text)) & held))
unseen = np.array(unseen)

for spec in args.models:
    training, seed = spec.rsplit(":", 1)
    trained = trained_pgae(training, "book", int(seed), device="cpu", progress=False)
    heard = trained.model.language_encoder.encode_texts(texts)
    back = predict(trained.model, test, trained.normaliser, "repeat language", language=heard)
    print(f"{spec}: validation readback {100 * back.correct.mean():.2f}% "
          f"(held-out words {100 * back.correct[unseen].mean():.2f}% of {unseen.sum()}, "
          f"others {100 * back.correct[~unseen].mean():.2f}%)", flush=True)
