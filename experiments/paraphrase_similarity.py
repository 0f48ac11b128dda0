"""How far can the frozen transformer alone take a paraphrase? Nearest fixed-vocabulary instruction by cosine.

    python experiments/paraphrase_similarity.py [--model NAME] [--out experiments/out/paraphrase_similarity.json]

PGAE-BERT sees a paraphrase only as the transformer's sentence vector. Before
blaming (or crediting) PGAE, ask the transformer itself: for each of the 108
held-out paraphrases (``pgae_lite/freeform/paraphrases.tsv``), which of the 288
fixed-vocabulary inputs "execute ACTION COLOUR SPEED" that PGAE-BERT was
trained on has the most similar sentence vector (cosine)? Its meaning is
counted right when action, colour and speed all match; each slot is also
counted alone. No training, no simulator: seconds on a CPU.
"""
from __future__ import annotations

import argparse
import json
from collections import Counter
from pathlib import Path

import torch

from pgae_lite.bert.pretrained import PretrainedLanguageEncoder, fixed_token_rows, input_text
from pgae_lite.freeform.paraphrases import load_paraphrases
from pgae_lite.world.words import VOCABULARY, parse_description

ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
ap.add_argument("--model", default=None, help="Hugging Face name or folder (default: the shipped all-MiniLM-L6-v2)")
ap.add_argument("--out", default="experiments/out/paraphrase_similarity.json")
args = ap.parse_args()

encoder = PretrainedLanguageEncoder(args.model)
rows = [k for k, text in enumerate(encoder.texts) if text.startswith("execute ")]          # the 288 trained inputs
tokens = fixed_token_rows()                                          # the same inputs as vocabulary indices
meanings = [parse_description(" ".join(VOCABULARY[w] for w in tokens[k, 1:4].tolist())) for k in rows]
paraphrases = load_paraphrases()
unit = torch.nn.functional.normalize
similarity = unit(encoder.encode_texts([input_text("execute", p.text) for p in paraphrases]), dim=1) \
    @ unit(encoder.table[rows], dim=1).T                                                     # (108, 288)
cosine, nearest = similarity.max(1)

right = Counter()
per_action = Counter()
episodes = []
for p, k, c in zip(paraphrases, nearest.tolist(), cosine.tolist()):
    got = meanings[k]
    slots = {"action": got[0] == p.action, "colour": got[1] == p.colour, "speed": got[2] == p.speed}
    right.update({**slots, "all three": all(slots.values())})
    per_action[p.action] += all(slots.values())
    episodes.append({"text": p.text, "meaning": " ".join(p.meaning), "nearest": encoder.texts[rows[k]],
                     "cosine": round(c, 3), "right": all(slots.values())})

n = len(paraphrases)
summary = {name: round(100 * v / n, 1) for name, v in right.items()}
summary.update({f"{a} (all three)": round(100 * v / (n / 3), 1) for a, v in per_action.items()})
print(f"{encoder.name}: the nearest of the 288 trained inputs has the paraphrase's meaning (% of {n})")
for name, value in summary.items():
    print(f"  {name:24s} {value:5.1f}")
Path(args.out).parent.mkdir(parents=True, exist_ok=True)
Path(args.out).write_text(json.dumps({"model": encoder.name, "summary": summary, "paraphrases": episodes}, indent=1))
print(f"written to {args.out}")
