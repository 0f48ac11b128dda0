"""The most any read-out of the frozen transformer gets from the paraphrases: trained probes.

    python experiments/paraphrase_readout.py [--model NAME] [--carriers 20]
                                             [--out experiments/out/paraphrase_readout.json]

PGAE-BERT reads a sentence only through the frozen transformer. Here small
classifiers are trained on the transformer's outputs for the sentences
PGAE-BERT can be trained on, and tested on the 108 held-out paraphrases
(``pgae_lite/freeform/paraphrases.tsv``): they predict action, colour and speed, and a
paraphrase counts when all three are right. Two read-outs:

- ``sentence``: one linear layer on the mean-pooled sentence vector, the
  vector PGAE-BERT's GMU receives;
- ``tokens``: per slot, an attention pooling over the token vectors (a learned
  score per token, softmax) and a linear layer: a richer read-out than
  PGAE-BERT has.

Two training sets: the 288 fixed-vocabulary instructions ("execute push red
slowly", 8 synonym variants of each of the 36 meanings); and the same plus
``--carriers`` generated sentences per meaning that put the same vocabulary
words in other sentences ("kindly move up this scarlet item, unhurriedly").
The carrier words are checked to be disjoint from the held-out paraphrases'
words, so every content word of a paraphrase that is not in the vocabulary
("shove", "crimson", "gently") must be understood by the transformer itself.
No simulator, no PGAE: a few minutes on a CPU (4 min on one core next to two trainings).
"""
from __future__ import annotations

import argparse
import itertools
import json
import random
import re
from collections import Counter
from pathlib import Path

import torch

from pgae_lite.bert.pretrained import PretrainedLanguageEncoder, input_text
from pgae_lite.freeform.paraphrases import load_paraphrases
from pgae_lite.world.words import ACTIONS, COLOURS, SPEEDS, SYNONYMS

ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
ap.add_argument("--model", default=None, help="Hugging Face name or folder (default: the shipped all-MiniLM-L6-v2)")
ap.add_argument("--carriers", type=int, default=20, help="generated carrier sentences per meaning (default: 20)")
ap.add_argument("--out", default="experiments/out/paraphrase_readout.json")
args = ap.parse_args()
torch.manual_seed(0)
rng = random.Random(0)

SLOTS = {"action": ACTIONS, "colour": COLOURS, "speed": SPEEDS}
MEANINGS = list(itertools.product(ACTIONS, COLOURS, SPEEDS))                   # the 36 meanings
WORDS = {w: [w, SYNONYMS[w].replace("-", " ")] for w in (*ACTIONS, *COLOURS, *SPEEDS)}
LEADS = ["", "kindly", "robot,", "let's", "your task:", "go on,"]
OBJECTS = ["object", "item", "brick", "thing", "one"]
FORMS = ["{lead} {a} the {c} {o} {s}", "{lead} {s}, {a} the {c} {o}", "{a} the {o} that is {c}, {s}",
         "{lead} {a} this {c} {o} {s}"]


def carrier(meaning: tuple[str, str, str]) -> str:
    a, c, s = (rng.choice(WORDS[w]) for w in meaning)
    text = rng.choice(FORMS).format(lead=rng.choice(LEADS), a=a, c=c, s=s, o=rng.choice(OBJECTS))
    return " ".join(text.split())


def words(text: str) -> set[str]:
    return set(re.findall(r"[a-z']+", text.lower()))


held = load_paraphrases()
fixed = [(" ".join(v), m) for m in MEANINGS for v in itertools.product(*(WORDS[w] for w in m))]    # 288
carriers = [(carrier(m), m) for m in MEANINGS for _ in range(args.carriers)]
vocabulary_words = set().union(*(words(" ".join(v)) for v in WORDS.values()))
shared = set().union(*(words(t) for t, _ in carriers)) - vocabulary_words - {"the"}
shared &= set().union(*(words(p.text) for p in held))
assert not shared, f"carrier words also in the held-out paraphrases: {sorted(shared)}"

encoder = PretrainedLanguageEncoder(args.model)
tf = encoder.transformer


@torch.no_grad()
def token_states(texts: list[str], length: int = 40) -> tuple[torch.Tensor, torch.Tensor]:
    """Texts (signal phrase first) -> token vectors (N, length, D) and mask (N, length)."""
    enc = tf.tokenizer([input_text("execute", t) for t in texts], padding="max_length", max_length=length,
                       truncation=True, return_tensors="pt")
    return tf.model(**enc).last_hidden_state.float(), enc["attention_mask"].bool()


def readout(kind: str, dim: int, classes: int) -> tuple[torch.nn.Module, callable]:
    linear, score = torch.nn.Linear(dim, classes), torch.nn.Linear(dim, 1)
    if kind == "sentence":                                                  # mean over real tokens, as PGAE-BERT
        return linear, lambda h, m: linear((h * m[..., None]).sum(1) / m.sum(1, keepdim=True))
    def attend(h, m):
        a = score(h).squeeze(-1).masked_fill(~m, -1e9).softmax(1)             # (N, tokens) attention weights
        return linear((a[..., None] * h).sum(1))
    return torch.nn.ModuleList([linear, score]), attend


def accuracy(kind: str, train: list[tuple[str, tuple]], test_h, test_m) -> tuple[dict[str, float], list[dict]]:
    """Per slot and for all three: % of the held-out paraphrases read right; and the misses."""
    h, m = token_states([t for t, _ in train])
    right = torch.ones(len(held), dtype=torch.bool)
    out, misses = {}, []
    for k, (slot, names) in enumerate(SLOTS.items()):
        target = torch.tensor([names.index(mn[k]) for _, mn in train])
        expected = torch.tensor([names.index(p.meaning[k]) for p in held])
        module, f = readout(kind, h.shape[-1], len(names))
        opt = torch.optim.Adam(module.parameters(), 1e-2, weight_decay=1e-3)
        for _ in range(400):
            opt.zero_grad()
            torch.nn.functional.cross_entropy(f(h, m), target).backward()
            opt.step()
        with torch.no_grad():
            got = f(test_h, test_m).argmax(1)
        ok = got == expected
        out[slot] = round(100 * ok.float().mean().item(), 1)
        misses += [{"slot": slot, "text": p.text, "meant": p.meaning[k], "read": names[g]}
                   for p, g, o in zip(held, got.tolist(), ok.tolist()) if not o]
        right &= ok
    out["all three"] = round(100 * right.float().mean().item(), 1)
    return out, misses


test_h, test_m = token_states([p.text for p in held])
results = {}
print(f"{encoder.name}: held-out paraphrases read right (% of {len(held)})")
print(f"{'read-out':10s} {'trained on':34s} {'action':>7s} {'colour':>7s} {'speed':>7s} {'all three':>10s}")
for kind in ("sentence", "tokens"):
    for name, train in (("the 288 instructions", fixed), (f"+ {args.carriers} carrier sentences per meaning",
                                                          fixed + carriers)):
        r, misses = accuracy(kind, train, test_h, test_m)
        results[f"{kind} / {name}"] = r
        print(f"{kind:10s} {name:34s} {r['action']:7.1f} {r['colour']:7.1f} {r['speed']:7.1f} {r['all three']:10.1f}")
common = Counter((x["slot"], x["meant"], x["read"]) for x in misses).most_common(6)
print("the last row's most frequent misses: " + "; ".join(f"{s} {a} read as {b} ({n})" for (s, a, b), n in common))
Path(args.out).parent.mkdir(parents=True, exist_ok=True)
Path(args.out).write_text(json.dumps({"model": encoder.name, "carriers": args.carriers, "results": results,
                                      "misses_of_last_row": misses,
                                      "examples": [t for t, _ in carriers[::97]]}, indent=1))
print(f"e.g. {carriers[0][0]!r}, {carriers[-1][0]!r}\nwritten to {args.out}")
