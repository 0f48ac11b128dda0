"""The ceiling of PGAE-BERT's frozen sentence encoder with language augmentation.

    python benchmarks/readout_phrasings.py [--per-meaning 60] [--seeds 0 1 2]
                                           [--steps 400] [--threads 2]

Small read-outs (logistic regression, and an MLP with one hidden layer) learn
(action, colour, speed) from the sentence vector of ``execute <text>``, the
input PGAE-BERT's GMU gets. They are trained either on the dataset's 288
descriptions (each meaning's 8 synonym variants: the ``canonical`` baseline)
or on those plus ``--per-meaning`` generated phrasings of each of the 36
meanings (pgae_lite.bert.phrasings, a new set per seed: ``augmented``). Accuracy
(all three right) on the 108 held-out paraphrases (pgae_lite.bert.paraphrases),
on those with a word no augmented training sentence has (``new_word``), and
on those where some slot says its meaning with none of the lexicon phrases
the augmented training sentences used for that meaning (``new_slot_phrase``).
``held_out_words`` trains on a lexicon with a third of its one-word phrases
held out (another third per seed): its ``new_*`` subsets are the paraphrases
with words never seen in training, ``held new_*`` the same sentences for the
other read-outs, and ``probe`` generated sentences that use the held-out
words (a measure that does not look at the test sentences). Writes
results/readout_phrasings.json.
"""
from __future__ import annotations

import itertools
import random

import torch
from harness import Benchmark

from pgae_lite.world.words import (ACTIONS, COLOURS, SPEEDS, SYNONYMS,
                                 equivalent_descriptions)
from pgae_lite.bert.paraphrases import load_paraphrases
from pgae_lite.bert.phrase_lexicon import LEXICON, SLOTS, words_of
from pgae_lite.bert.phrasings import gerund, phrasings
from pgae_lite.bert.pretrained import PretrainedLanguageEncoder, input_text

MEANINGS = list(itertools.product(ACTIONS, COLOURS, SPEEDS))
MEANING_OF = dict(zip(SLOTS, (ACTIONS, COLOURS, SPEEDS)))
SIZES = (len(ACTIONS), len(COLOURS), len(SPEEDS))


class Embedder:
    """Sentence vectors of ``execute <text>``; each text is encoded once."""

    def __init__(self):
        self.encoder, self.done = PretrainedLanguageEncoder(), {}

    def __call__(self, texts: list[str]) -> torch.Tensor:
        new = [t for t in dict.fromkeys(texts) if t not in self.done]
        if new:
            vectors = self.encoder.encode_texts([input_text("execute", t) for t in new])
            self.done.update(zip(new, vectors))
        return torch.stack([self.done[t] for t in texts])


def labels(meanings: list[tuple[str, str, str]]) -> torch.Tensor:
    """(action, colour, speed) -> class indices (N, 3)."""
    return torch.tensor([[ACTIONS.index(a), COLOURS.index(c), SPEEDS.index(s)]
                         for a, c, s in meanings])


def train_readout(x: torch.Tensor, y: torch.Tensor, hidden: int, seed: int,
                  steps: int):
    """A read-out from standardised vectors to the three slots; returns predict(x)."""
    torch.manual_seed(seed)
    mean, std = x.mean(0), x.std(0) + 1e-6
    layers = [torch.nn.Linear(x.shape[1], hidden), torch.nn.ReLU(),
              torch.nn.Linear(hidden, sum(SIZES))] if hidden else \
        [torch.nn.Linear(x.shape[1], sum(SIZES))]
    net = torch.nn.Sequential(*layers)
    opt = torch.optim.Adam(net.parameters(), 1e-2, weight_decay=1e-3)
    for _ in range(steps):                       # full batch
        logits = net((x - mean) / std).split(SIZES, 1)
        loss = sum(torch.nn.functional.cross_entropy(z, y[:, i])
                   for i, z in enumerate(logits))
        opt.zero_grad()
        loss.backward()
        opt.step()

    @torch.no_grad()
    def predict(v: torch.Tensor) -> torch.Tensor:
        logits = net((v - mean) / std).split(SIZES, 1)
        return torch.stack([z.argmax(1) for z in logits], 1)
    return predict


def slot_phrases(slot: str, meaning: str) -> list[tuple[str, ...]]:
    """The lexicon's phrases of one meaning, word tuples (verbs also in -ing form)."""
    phrases = list(LEXICON.phrases(slot)[meaning])
    if slot == "action":
        verbs = (*LEXICON.verbs[meaning], *LEXICON.steered[meaning])
        phrases += [gerund(v) for v in verbs]
    return [tuple(words_of(p)) for p in phrases]


def has(words: list[str], phrase: tuple[str, ...]) -> bool:
    return any(tuple(words[i:i + len(phrase)]) == phrase for i in range(len(words)))


def subsets(train: list[tuple[str, tuple]], test: list) -> dict[str, list[int]]:
    """Test sentences with a word not in ``train``, or a slot said by no phrase seen."""
    vocabulary = {w for text, _ in train for w in words_of(text)}
    seen = {(slot, m): set() for slot in SLOTS for m in MEANING_OF[slot]}
    for text, meaning in train:
        words = words_of(text)
        for slot, m in zip(SLOTS, meaning):
            seen[slot, m].update(p for p in slot_phrases(slot, m) if has(words, p))
    out = {"new_word": [i for i, p in enumerate(test)
                        if not set(words_of(p.text)) <= vocabulary]}
    for k, slot in enumerate(SLOTS):
        out[f"new_{slot}_phrase"] = [
            i for i, p in enumerate(test)
            if not any(has(words_of(p.text), ph) for ph in seen[slot, p.meaning[k]])]
    new = set().union(*(out[f"new_{slot}_phrase"] for slot in SLOTS))
    out["new_slot_phrase"] = sorted(new)
    return out


def accuracy(predict, x: torch.Tensor, y: torch.Tensor, rows: list[int] | None = None):
    rows = list(range(len(y))) if rows is None else rows
    if not rows:
        return None
    right = (predict(x[rows]) == y[rows]).all(1).float().mean().item()
    return round(100 * right, 1)


def held_out_words(seed: int) -> list[str]:
    """A third of the one-word colour, speed and verb phrases (no dataset word).

    Seeds 0, 1 and 2 hold out three disjoint thirds: together, every such word.
    """
    trained = {w for pair in SYNONYMS.items() for word in pair for w in words_of(word)}
    words = sorted({p for part in (LEXICON.colours, LEXICON.speeds, LEXICON.verbs)
                    for ps in part.values() for p in ps
                    if " " not in p and "-" not in p} - trained)
    random.Random(0).shuffle(words)
    return words[seed % 3::3]


def main() -> None:
    bench = Benchmark("readout_phrasings", __doc__, seeds=[0, 1, 2])
    bench.parser.add_argument("--per-meaning", type=int, default=60)
    bench.parser.add_argument("--steps", type=int, default=400)
    bench.parser.add_argument("--hidden", type=int, default=256)
    args = bench.parse()
    embed, test = Embedder(), load_paraphrases()
    test_x, test_y = embed([p.text for p in test]), labels([p.meaning for p in test])
    canonical = [(" ".join(d).replace("-", " "), m) for m in MEANINGS
                 for d in equivalent_descriptions(*m)]
    rows, sizes = [], []
    for seed in args.seeds:
        held = held_out_words(seed)
        trainings = {"canonical": canonical}
        for name, lexicon in (("augmented", LEXICON),
                              ("held_out_words", LEXICON.without(*held))):
            trainings[name] = canonical + [
                (t, m) for m in MEANINGS
                for t in phrasings(*m, args.per_meaning, seed=seed, lexicon=lexicon)]
        probe = [(t, m) for m in MEANINGS for t in phrasings(*m, 40, seed=seed + 1000)
                 if set(held) & set(words_of(t))]
        probe_x, probe_y = embed([t for t, _ in probe]), labels([m for _, m in probe])
        parts = {name: subsets(train, test) for name, train in trainings.items()}
        sizes.append({"seed": seed, "held_out": len(held),
                      "probe_sentences": len(probe),
                      **{f"{name} {k}": len(v) for name, p in parts.items()
                         for k, v in p.items()}})
        print(sizes[-1], flush=True)
        for (name, train), (readout, hidden) in itertools.product(
                trainings.items(), (("logistic", 0), ("mlp", args.hidden))):
            x, y = embed([t for t, _ in train]), labels([m for _, m in train])
            predict = train_readout(x, y, hidden, seed, args.steps)
            rows.append({
                "seed": seed, "training": name, "readout": readout,
                "train_sentences": len(train), "train_%": accuracy(predict, x, y),
                "paraphrases_%": accuracy(predict, test_x, test_y),
                **{f"{k}_%": accuracy(predict, test_x, test_y, v)
                   for k, v in parts[name].items()},
                **{f"held {k}_%": accuracy(predict, test_x, test_y, v)
                   for k, v in parts["held_out_words"].items()
                   if name != "held_out_words"},
                "probe_%": accuracy(predict, probe_x, probe_y)})
            print(rows[-1], flush=True)
    summary = {}
    for name, readout in itertools.product(trainings, ("logistic", "mlp")):
        mine = [r for r in rows if r["training"] == name and r["readout"] == readout]
        summary[f"{name} {readout}"] = {
            k: round(sum(r[k] for r in mine) / len(mine), 1) for k in mine[0]
            if k.endswith("_%") and all(r[k] is not None for r in mine)}
        print(f"{name} {readout}", summary[f"{name} {readout}"])
    bench.write({"model": embed.encoder.name, "per_meaning": args.per_meaning,
                 "steps": args.steps, "hidden": args.hidden,
                 "test_sentences": len(test), "summary": summary,
                 "subset_sizes": sizes, "rows": rows})

if __name__ == "__main__":
    main()
