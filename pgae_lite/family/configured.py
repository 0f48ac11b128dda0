"""Table 1's cells for a model that must be configured per direction: PRAE and PVAE.

PGAE paper, Sec. 4: PVAE "has to be set in the specific configuration" for each task, so it
"cannot output joint values when it is configured to be used for action-to-language
translation", and when it executes a description it "is not trained to generate descriptions
(<EOS> in this case)" (N.A.). Each of the four test signals is one configuration here::

    | signal          | path                                | words  | joints |
    |-----------------|-------------------------------------|--------|--------|
    | describe        | action encoder -> language decoder   | yes    | N.A.   |
    | repeat language | language encoder -> language decoder | yes    | N.A.   |
    | execute         | language encoder -> action decoder   | N.A.   | yes    |
    | repeat action   | action encoder -> action decoder     | N.A.   | yes    |

and a cell the configuration cannot produce is ``None`` (N.A.). The words are judged and the
joints measured exactly as :func:`pgae_lite.evaluate.evaluate` does for PGAE: the same
criterion (one of the 8 equivalent descriptions), the same nRMSE over the valid steps, and a
description given to sample i is its alternative i mod 8.
"""
from __future__ import annotations

import numpy as np
import torch

from pgae_lite.data.dataset import Normaliser, PGAEDataset
from pgae_lite.evaluate import Predictions, nrmse
from pgae_lite.model.signals import make_batch, signal_ids
from pgae_lite.util.checks import instance_of
from pgae_lite.world.words import DEFAULT_LEXICON, TEST_SIGNALS, decode, is_correct

WORDS_OUT = ("describe", "repeat language")      # the configurations whose output is words
LANGUAGE_IN = ("execute", "repeat language")      # and those that read the description


@torch.no_grad()
def configured_predictions(model, data: PGAEDataset, normaliser: Normaliser, signal: str,
                           batch_size: int = 256) -> Predictions:
    """``model`` configured for ``signal`` on every sample of ``data``, as :class:`~pgae_lite.evaluate.Predictions`.

    What the configuration cannot produce stays empty: no texts (``""``, and ``correct`` False)
    when it outputs joints, joints of NaN when it outputs words. No gate: ``gate`` is (N, 0).
    """
    model.eval()
    tensors = normaliser.tensors(data, next(model.parameters()).device)
    texts, joints, targets = [], [], []
    for s in range(0, len(data), batch_size):
        index = torch.arange(s, min(len(data), s + batch_size))
        b = make_batch(tensors, index, signal_ids("repeat both", len(index)), index % 8)
        if signal in LANGUAGE_IN:
            code = model.language_code(b.lang_tokens, b.lang_lengths)               # the description
        else:
            code = model.action_code(b.action_input, b.action_lengths)
        target = torch.cat([b.start_joints[:, None], b.joint_target], 1)            # (B, T, 5)
        if signal in WORDS_OUT:
            texts += [decode(row, DEFAULT_LEXICON) for row in model.language_decoder(code).argmax(-1).cpu()]
            pred = torch.full_like(target, float("nan"))
        else:
            texts += [""] * len(index)
            out = model.action_decoder(code, b.dec_vision, b.start_joints, b.joint_mask.sum(1))
            pred = normaliser.joints_to_data(torch.cat([b.start_joints[:, None], out], 1))
        joints.append(pred.cpu().numpy())
        targets.append(normaliser.joints_to_data(target).cpu().numpy())
    mask = data.mask[..., None]
    correct = np.array([signal in WORDS_OUT and is_correct(t, [tuple(DEFAULT_LEXICON.vocabulary[w] for w in alt)
                                                               for alt in data.descriptions[i]])
                        for i, t in enumerate(texts)])
    return Predictions(signal, np.asarray(data.ids), texts,
                       np.where(mask, np.concatenate(joints), np.nan).astype(np.float32),
                       np.where(mask, np.concatenate(targets), np.nan).astype(np.float32),
                       correct, np.zeros((len(data), 0), np.float32))


def evaluate_configured(model, data: PGAEDataset, normaliser: Normaliser, split: str = "test",
                        joint_range: float | None = None
                        ) -> tuple[dict[str, dict[str, float | None]], dict[str, Predictions]]:
    """Table 1's cells of a configured model (PRAE, PVAE), in %, None where N.A.; and the predictions."""
    for method in ("language_code", "action_code", "language_decoder", "action_decoder"):
        if not hasattr(model, method):
            raise TypeError(f"evaluate_configured takes a model with separate codes (PRAE, PVAE); "
                            f"{type(model).__name__} has no {method}: for PGAE use pgae_lite.evaluate.evaluate")
    instance_of("data", data, PGAEDataset, "a PGAEDataset")
    joint_range = joint_range or data.joint_range()
    subset = data.split(split)
    cells, preds = {}, {}
    for signal in TEST_SIGNALS:
        p = configured_predictions(model, subset, normaliser, signal)
        cell = {"accuracy": None, "nrmse": None, "nrmse_padded": None, "n": len(subset)}
        if signal in WORDS_OUT:
            cell["accuracy"] = 100 * float(p.correct.mean())
        else:
            cell["nrmse"], cell["nrmse_padded"] = nrmse(p, joint_range)
        cells[signal], preds[signal] = cell, p
    return cells, preds


__all__ = ["LANGUAGE_IN", "WORDS_OUT", "configured_predictions", "evaluate_configured"]
