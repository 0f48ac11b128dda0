"""Pooling probe: how much of an instruction's meaning a classifier reads from frozen token vectors.

    python experiments/pooling_probe.py [--per-meaning 60] [--threads 2]

No PGAE: the frozen transformer (all-MiniLM-L6-v2) encodes K generated
phrasings of each of the 36 meanings (grammar seed 0, :mod:`pgae_lite.freeform.phrasings`)
with ``repeat language`` in front; a classifier of the 36 meanings is trained on
them through one pooling (the mean, the maximum, or an attention pooling with
1, 4 or 8 heads, :class:`pgae_lite.freeform.attention_pooling.AttentionPooling`) and a
linear or one-hidden-layer head, and scored on 12 phrasings per meaning of
another grammar seed (4242, the validation sentences of
``validation_readback.py``). The test paraphrases are never read.
"""
import argparse
import itertools

import torch

from pgae_lite.bert.pretrained import input_text, load_transformer
from pgae_lite.freeform.attention_pooling import AttentionPooling, padded_token_vectors
from pgae_lite.freeform.phrasings import phrasings
from pgae_lite.world.words import SLOTS

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--per-meaning", type=int, default=60)
parser.add_argument("--threads", type=int, default=2)
args = parser.parse_args()
torch.set_num_threads(args.threads)
MEANINGS = list(itertools.product(*SLOTS))
tf = load_transformer()


def sentences(k: int, seed: int):
    texts = [input_text("repeat language", t) for m in MEANINGS for t in phrasings(*m, k, seed=seed)]
    states, mask = padded_token_vectors(tf, texts)                       # (N, T, D), (N, T)
    return states, mask, torch.arange(len(MEANINGS)).repeat_interleave(k)


train, valid = sentences(args.per_meaning, 0), sentences(12, 4242)


class Probe(torch.nn.Module):
    def __init__(self, pooling: str, hidden: int):
        super().__init__()
        self.pooling = pooling
        heads = int(pooling[len("attention"):] or 1) if pooling.startswith("attention") else 0
        self.attention = AttentionPooling(384, heads) if heads else None
        self.head = (torch.nn.Linear(384, 36) if not hidden else torch.nn.Sequential(
            torch.nn.Linear(384, hidden), torch.nn.Tanh(), torch.nn.Linear(hidden, 36)))

    def forward(self, states, mask):
        if self.attention is not None:
            f = self.attention(states, mask)
        elif self.pooling == "max":
            f = states.masked_fill(~mask[..., None], -1e4).max(1).values
        else:
            f = (states * mask[..., None]).sum(1) / mask.sum(1, keepdim=True)
        return self.head(f)


torch.manual_seed(0)
for pooling in ("mean", "max", "attention1", "attention4", "attention8"):
    for hidden in (0, 256):
        probe = Probe(pooling, hidden)
        optimiser = torch.optim.AdamW(probe.parameters(), 3e-3, weight_decay=0.01)
        for step in range(1500):
            i = torch.randint(len(train[2]), (128,))
            loss = torch.nn.functional.cross_entropy(probe(train[0][i], train[1][i]), train[2][i])
            optimiser.zero_grad()
            loss.backward()
            optimiser.step()
        with torch.no_grad():
            accuracy = (probe(valid[0], valid[1]).argmax(1) == valid[2]).float().mean()
        print(f"{pooling:10s} {'linear' if not hidden else f'{hidden} hidden':10s} "
              f"validation accuracy {100 * accuracy:.1f}%", flush=True)
