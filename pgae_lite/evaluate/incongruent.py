"""Incongruent input: the action shown and the description read disagree; which one does a model follow?

PTAE paper (Özdemir et al. 2023), Sec. 4, after the authors' ``inference_conflict.py``. Two
experiments on the test samples of a model that reads both modalities (PGAE, PTAE):

- **language conflicts**, signal describe: the model sees the action, and reads a description
  with one word swapped for another of its slot (the action word, the colour word, or the
  speed word; a synonym stays a synonym). Right = it describes the action it sees; we also
  count how often it says the swapped-in words instead.
- **action conflicts**, signal execute: the model reads the description and, in place of the
  first frame alone, sees a whole recording of another action in the same scene (another
  action on the same cube, the same action on the other cube, or the other speed). Its
  joints are measured (nRMSE) against the described action and against the one it was shown.

::

    | conflict | signal   | language in          | action in                  | right when            |
    |----------|----------|----------------------|----------------------------|-----------------------|
    | language | describe | a swapped description | the sample's action        | it describes the action |
    | action   | execute  | the description       | another pattern's recording | it moves as described  |

The swaps are drawn once from a seed: the same seed, the same conflicts.
"""
from __future__ import annotations

import numpy as np
import torch

from pgae_lite.data.dataset import PGAEDataset
from pgae_lite.data.normaliser import Normaliser
from pgae_lite.evaluate.table1 import joint_nrmse
from pgae_lite.model.signals import SIGNAL_TOKEN, make_batch, signal_ids
from pgae_lite.world.patterns import pattern_number, pattern_parts
from pgae_lite.world.words import (
    ACTIONS,
    CANONICAL,
    DEFAULT_LEXICON,
    DESCRIPTIONS,
    SIGNALS,
    SLOTS,
    SYNONYMS,
    VOCABULARY,
    WORD_INDEX,
    decode,
    equivalent_descriptions,
    is_correct,
)

LANGUAGE_CONFLICTS = ("action", "colour", "speed")      # which word of the description is swapped
ACTION_CONFLICTS = ("action", "position", "speed")      # what differs in the recording shown


def _nrmse(joints: np.ndarray, target: np.ndarray, mask: np.ndarray, joint_range: float) -> float:
    """Table 1's nRMSE (%) of joints (n, T, 5) against target over the steps that ``mask`` (n, T) holds."""
    return joint_nrmse(np.where(mask[..., None], joints, np.nan), target, joint_range)[0]


def swapped_words(words: np.ndarray, kind: str, rng: np.random.Generator) -> np.ndarray:
    """A description's 3 word indices with the ``kind`` word swapped for another of its slot (synonym kept)."""
    slot = LANGUAGE_CONFLICTS.index(kind)
    word = VOCABULARY[words[slot]]
    canonical = CANONICAL[word]
    other = rng.choice([w for w in SLOTS[slot] if w != canonical])
    out = words.copy()
    out[slot] = WORD_INDEX[SYNONYMS[other] if word != canonical else other]
    return out


def meanings(words: np.ndarray) -> list[tuple[str, ...]]:
    """The 8 equivalent descriptions of 3 word indices, as :func:`~pgae_lite.world.words.is_correct` reads them."""
    action, colour, speed = (CANONICAL[VOCABULARY[w]] for w in words)
    return equivalent_descriptions(action, colour, speed)


def shown_instead(data: PGAEDataset, test: np.ndarray, kind: str, rng: np.random.Generator) -> np.ndarray:
    """For each test sample, a recording (index into ``data``) of the pattern that differs by ``kind``."""
    by_pattern = {p: np.flatnonzero(data.pattern == p) for p in np.unique(data.pattern)}
    shown = []
    for i in test:
        speed, arrangement, action = pattern_parts(int(data.pattern[i]))
        verb, side = action % 3, action // 3                        # ACTION_SIDES: push, pull, slide; L then R
        if kind == "action":
            verb = rng.choice([v for v in range(len(ACTIONS)) if v != verb])
        elif kind == "position":
            side = 1 - side
        else:
            speed = 1 - speed
        candidates = by_pattern.get(pattern_number(speed, arrangement, 3 * side + verb))
        if candidates is None:
            raise ValueError(f"no recording of pattern {pattern_number(speed, arrangement, 3 * side + verb)} "
                             f"to show in place of sample {data.ids[i]}: the data lacks patterns")
        shown.append(rng.choice(candidates))
    return np.asarray(shown)


@torch.no_grad()
def incongruent_cells(model, data: PGAEDataset, normaliser: Normaliser, seed: int = 0) -> dict:
    """Both experiments on ``data``'s test split: per conflict, the share (%) described right or the nRMSE."""
    model.eval()
    device = next(model.parameters()).device
    tensors = normaliser.tensors(data, device)
    test = np.flatnonzero(data.is_test)
    index = torch.as_tensor(test)
    joint_range = data.joint_range()
    rng = np.random.default_rng(seed)
    out = {"language": {}, "action": {}, "n": len(test)}
    for kind in ("none", *LANGUAGE_CONFLICTS):
        b = make_batch(tensors, index, signal_ids("describe", len(test)), index % DESCRIPTIONS)
        words = data.descriptions[test, test % DESCRIPTIONS]                                    # (n, 3)
        read = words if kind == "none" else np.stack([swapped_words(w, kind, rng) for w in words])
        b.lang_tokens = torch.cat([torch.full((len(test), 1), SIGNAL_TOKEN + SIGNALS.index("describe")),
                                   torch.as_tensor(read), torch.zeros(len(test), 1, dtype=torch.long)], 1).to(device)
        b.lang_lengths = torch.full((len(test),), 5, device=device)                  # the description is read
        texts = [decode(row, DEFAULT_LEXICON) for row in model(b)["logits"].argmax(-1).cpu()]
        right = [is_correct(t, meanings(w)) for t, w in zip(texts, words)]
        followed = [is_correct(t, meanings(r)) for t, r in zip(texts, read)]
        out["language"][kind] = {"described right": 100 * float(np.mean(right)),
                                 "said the words read": 100 * float(np.mean(followed))}
    for kind in ("none", *ACTION_CONFLICTS):
        b = make_batch(tensors, index, signal_ids("execute", len(test)), index % DESCRIPTIONS)
        shown = test if kind == "none" else shown_instead(data, test, kind, rng)
        b.action_input = torch.cat([tensors["vision"][shown], tensors["joints"][shown]], 2)   # (n, T, 35)
        b.action_lengths = tensors["lengths"][shown]                                        # the whole recording
        joints = normaliser.joints_to_data(torch.cat([b.start_joints[:, None], model(b)["joints"]], 1)).cpu().numpy()
        both = data.mask[test] & data.mask[shown]                                    # steps both recordings have
        out["action"][kind] = {
            "nrmse to the described": _nrmse(joints, data.joints[test], data.mask[test], joint_range),
            "nrmse to the shown": _nrmse(joints, data.joints[shown], both, joint_range)}
    return out


__all__ = ["ACTION_CONFLICTS", "LANGUAGE_CONFLICTS", "incongruent_cells", "meanings",
           "shown_instead", "swapped_words"]
