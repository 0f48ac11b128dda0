"""Evaluation as in the paper's Table 1 (Sec. 4, "Results").

- Description accuracy: a generated description is correct when all its
  words match one of the 8 equivalent descriptions; for ``execute`` and
  ``repeat action`` the expected output is ``<EOS>`` alone.
- Joint error: nRMSE = sqrt(MSE) / (observed range of joint values), over the
  predicted steps 1..length-1 of each sample. ``nrmse_padded`` is the
  authors' convention: padded steps count as zero error in the mean (it
  reads about 14% lower on data with half the actions fast).

Signals that take a description in (execute, repeat language) feed test
sample i its alternative i mod 8, so every synonym is used equally often.

One evaluation for every model: a model says what it writes for each signal (``model.PATHS``:
words, joints or both), and a cell it has no path for is N.A., ``None``. PGAE and PTAE write both
for every signal; PRAE and PVAE, configured per direction, one each (paper Sec. 4: PVAE "cannot
output joint values when it is configured to be used for action-to-language translation", and
executing "is not trained to generate descriptions (<EOS> in this case)";
:mod:`pgae_lite.model.prae`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from pgae_lite.data.dataset import PGAEDataset
from pgae_lite.data.normaliser import Normaliser
from pgae_lite.model.signals import LANG_OUT, make_batch, signal_ids
from pgae_lite.util.checks import instance_of, positive_number, whole_number
from pgae_lite.util.errors import ArgumentError
from pgae_lite.world.words import (
    DEFAULT_LEXICON,
    DESCRIPTIONS,
    SIGNALS,
    TEST_SIGNALS,
    decode,
    is_correct,
    normalise_signal,
)

#: The paper's Table 1: (accuracy %, nRMSE %) per row and signal.
PAPER_TABLE: dict[str, dict[str, tuple[float, float]]] = {
    "PGAE": {"describe": (93.05, 0.23), "repeat language": (96.30, 0.37),
             "execute": (100.0, 0.44), "repeat action": (100.0, 0.44)},
    "PGAE-BERT": {"describe": (94.91, 0.21), "repeat language": (99.07, 0.33),
                  "execute": (100.0, 0.44), "repeat action": (100.0, 0.42)},
    "PGAE-self": {"describe": (80.56, 0.58), "repeat language": (93.98, 0.73),
                  "execute": (100.0, 0.79), "repeat action": (100.0, 0.89)},
    "PGAE-opposite": {"describe": (65.28, 2.40), "repeat language": (93.98, 0.73),
                      "execute": (100.0, 0.79), "repeat action": (100.0, 0.80)},
}


@dataclass
class Predictions:
    """A model's outputs for one signal on a set of samples (N of them)."""

    signal: str
    ids: np.ndarray        # (N,) sample names
    text: list[str]        # generated description, "" for <EOS> alone
    joints: np.ndarray     # (N, 100, 5) data units; step 0 = the given start joints; NaN past the length
    target: np.ndarray     # (N, 100, 5) what the joints should have been (same conventions)
    correct: np.ndarray    # (N,) bool, description criterion
    gate: np.ndarray       # (N, hidden) GMU gate values ((N, 0): a model without a gate, e.g. PTAE)


def check_model_inputs(model: torch.nn.Module, data: PGAEDataset, normaliser: Normaliser) -> None:
    """A one-sentence ArgumentTypeError unless the three are what their names say."""
    instance_of("model", model, torch.nn.Module, "a model (a PGAE, a torch.nn.Module)")
    instance_of("data", data, PGAEDataset, "a PGAEDataset")
    instance_of("normaliser", normaliser, Normaliser,
                "a Normaliser, e.g. Normaliser.fit(data.split('train'))")


@torch.no_grad()
def predict(model: torch.nn.Module, data: PGAEDataset, normaliser: Normaliser, signal: str,
            opposite: bool = False, batch_size: int = 256,
            tensors: dict[str, torch.Tensor] | None = None, language: torch.Tensor | None = None) -> Predictions:
    """Run ``model`` on every sample of ``data`` with one signal (decoders free-running).

    What the model has no path for stays empty: no text (``""``) where it writes no words, joints of NaN
    where it writes no joints (``model.PATHS``).

    ``tensors``: ``normaliser.tensors(data, device)`` when the caller has them already.
    ``language`` (N, D): precomputed language features, one row per sample, in place of
    the language encoder's (``model(batch, language=...)``), e.g. free text through
    :func:`pgae_lite.robot.instructions.instruction_features`: with ``"execute"`` the paper's
    execute (open loop: the recorded vision at every step) of those instructions.
    """
    check_model_inputs(model, data, normaliser)
    signal = normalise_signal(signal)
    instance_of("opposite", opposite, (bool, np.bool_), "True or False")
    whole_number("batch_size", batch_size, 1)
    instance_of("language", language, torch.Tensor, f"a tensor ({len(data)}, D)",
                optional=True)
    if language is not None and (language.dim() != 2 or len(language) != len(data)):
        raise ArgumentError(f"language must be a tensor of shape ({len(data)}, D), "
                            f"one row per sample of data; got shape "
                            f"{tuple(language.shape)}")
    lexicon = getattr(model, "lexicon", DEFAULT_LEXICON)         # the model's words
    model.eval()
    device = next(model.parameters()).device
    tensors = tensors or normaliser.tensors(data, device)
    n = len(data)
    texts, joints, targets, gates = [], [], [], []
    for s in range(0, n, batch_size):
        index = torch.arange(s, min(n, s + batch_size))
        batch = make_batch(tensors, index, signal_ids(signal, len(index)), index % DESCRIPTIONS,
                           torch.full((len(index),), opposite))
        if language is None:
            out = model(batch)                               # decoders free-running, greedy words
        else:
            out = model(batch, language=language[s:s + len(index)].to(device))
        target = torch.cat([batch.start_joints[:, None], batch.joint_target], 1)    # (B, T, 5)
        texts += ([decode(row, lexicon) for row in out["logits"].argmax(-1).cpu()] if "logits" in out
                  else [""] * len(index))
        pred = (torch.cat([batch.start_joints[:, None], out["joints"]], 1) if "joints" in out
                else torch.full_like(target, float("nan")))                             # (B, T, 5)
        joints.append(normaliser.joints_to_data(pred).cpu().numpy())
        targets.append(normaliser.joints_to_data(target).cpu().numpy())
        gates.append(out["gate"].cpu().numpy() if "gate" in out else np.zeros((len(index), 0), np.float32))
    mask = data.mask[..., None]
    joints_arr = np.where(mask, np.concatenate(joints), np.nan).astype(np.float32)
    target_arr = np.where(mask, np.concatenate(targets), np.nan).astype(np.float32)
    expected_text = LANG_OUT[SIGNALS.index(signal)]
    correct = np.array([
        is_correct(t, [tuple(lexicon.vocabulary[w] for w in alt)
                       for alt in data.descriptions[i]] if expected_text else None)
        for i, t in enumerate(texts)])
    return Predictions(signal, np.asarray(data.ids), texts, joints_arr, target_arr, correct,
                       np.concatenate(gates))


def joint_nrmse(joints: np.ndarray, target: np.ndarray, joint_range: float) -> tuple[float, float]:
    """Joints (..., T, 5) against their target over the predicted steps 1.. (step 0 is given), NaN where a sample
    has no step: (nRMSE over the valid steps, nRMSE the authors' padded way), both in %. Every nRMSE of the book."""
    err = (joints[..., 1:, :] - target[..., 1:, :]) ** 2             # step 0 is given, not predicted
    valid = ~np.isnan(err)
    sq = np.nansum(err)
    mse_valid = sq / valid.sum()
    mse_padded = sq / err.size                                       # padded steps count as 0 error
    return 100 * float(np.sqrt(mse_valid)) / joint_range, 100 * float(np.sqrt(mse_padded)) / joint_range


def nrmse(pred: Predictions, joint_range: float) -> tuple[float, float]:
    """(nRMSE over valid predicted steps, nRMSE the authors' padded way) of one signal's predictions, both in %."""
    instance_of("pred", pred, Predictions, "the Predictions of predict()")
    return joint_nrmse(pred.joints, pred.target, positive_number("joint_range", joint_range))


def evaluate(model: torch.nn.Module, data: PGAEDataset, normaliser: Normaliser, split: str = "test",
             opposite: bool = False, joint_range: float | None = None
             ) -> tuple[dict[str, dict[str, float | None]], dict[str, Predictions]]:
    """Table 1 cells for the four test signals: accuracy, nRMSE and padded nRMSE (all %), None where the
    model has no path for them (N.A., ``model.PATHS``).

    ``joint_range`` defaults to the observed range over the whole dataset.
    """
    check_model_inputs(model, data, normaliser)
    if joint_range is None:
        joint_range = data.joint_range()
    else:
        joint_range = positive_number("joint_range", joint_range)
    subset = data.split(split)
    tensors = normaliser.tensors(subset, next(model.parameters()).device)
    results, preds = {}, {}
    for signal in TEST_SIGNALS:
        p = predict(model, subset, normaliser, signal, opposite=opposite, tensors=tensors)
        writes = model.PATHS[signal]
        err, err_padded = nrmse(p, joint_range) if "joints" in writes else (None, None)
        results[signal] = {"accuracy": 100 * float(p.correct.mean()) if "words" in writes else None, "nrmse": err,
                           "nrmse_padded": err_padded, "n": int(len(p.correct))}
        preds[signal] = p
    return results, preds


def format_table(results: dict[str, dict[str, dict[str, float]]], paper_rows: dict[str, str] | None = None,
                 std: dict[str, dict[str, dict[str, float]]] | None = None) -> str:
    """Table 1 as text: each of our rows, followed by the paper's row it reproduces.

    ``results`` maps a row name (e.g. ``"PGAE (ours)"``) to :func:`evaluate`'s
    first return value (or a mean over seeds); ``paper_rows`` maps it to a row of
    :data:`PAPER_TABLE`; ``std``, if given, holds each cell's standard deviation
    over seeds, printed as ``mean ± std``.
    """
    paper_rows = paper_rows or {}
    unknown = sorted(set(paper_rows.values()) - set(PAPER_TABLE))
    if unknown:
        raise ArgumentError(f"paper_rows names {unknown[0]!r}, not a row of the "
                            f"paper's Table 1; the rows are: {', '.join(PAPER_TABLE)}")
    lacking = sorted(set(results) - set(std)) if std is not None else []
    if lacking:
        raise ArgumentError(f"std has no cells for the row {lacking[0]!r}; give it "
                            "every row of results")
    for name, cells in [*results.items(), *(std or {}).items()]:
        missing = [s for s in TEST_SIGNALS if s not in cells]
        if missing:
            raise ArgumentError(f"the cells of {name!r} lack the signal(s) "
                                f"{', '.join(missing)}; each row needs "
                                f"{', '.join(TEST_SIGNALS)} (as evaluate() returns "
                                "them)")

    def cell(name: str, signal: str, key: str, fmt: str) -> str:
        if results[name][signal][key] is None:                   # a configured model's N.A. (PRAE, PVAE)
            return f"{'N.A.':>17s}"
        value = format(results[name][signal][key], fmt)
        if std is not None:
            value += " ± " + format(std[name][signal][key], fmt)
        return f"{value:>17s}"

    head = f"{'':26s}" + "".join(f"{s:>17s}" for s in TEST_SIGNALS)
    lines = ["Description accuracy (%)", head]
    for name in results:
        lines.append(f"{name:26s}" + "".join(cell(name, s, "accuracy", ".2f") for s in TEST_SIGNALS))
        if name in paper_rows:
            row = PAPER_TABLE[paper_rows[name]]
            lines.append(f"{'  paper ' + paper_rows[name]:26s}" + "".join(f"{row[s][0]:17.2f}" for s in TEST_SIGNALS))
    lines += ["", "Joint nRMSE (%), valid steps" + ("" if std else " [authors' padded convention]"), head]
    for name, res in results.items():
        if std is None:
            lines.append(f"{name:26s}" + "".join(
                f"{'N.A.':>17s}" if res[s]['nrmse'] is None else
                f"{res[s]['nrmse']:9.3f} [{res[s]['nrmse_padded']:5.3f}]" for s in TEST_SIGNALS))
        else:
            lines.append(f"{name:26s}" + "".join(cell(name, s, "nrmse", ".3f") for s in TEST_SIGNALS))
        if name in paper_rows:
            row = PAPER_TABLE[paper_rows[name]]
            lines.append(f"{'  paper ' + paper_rows[name]:26s}" + "".join(f"{row[s][1]:17.2f}" for s in TEST_SIGNALS))
    return "\n".join(lines)
