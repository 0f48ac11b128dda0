"""The model from inside: gates, joints, training curves, the signals' table, which words go wrong.

Paper, Sec. 3 (the GMU's gate, the five signals, the action decoder's joints)
and Sec. 4 (Table 1: where descriptions go wrong). Helpers of the PGAE chapter
(04) and of the PGAE-BERT and opposite-agent chapters (05, 06): training curves
and gates of several models side by side, and which words a model confuses.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import torch
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from pgae_lite.data.dataset import PGAEDataset, description_text
from pgae_lite.model.signals import SignalBatch
from pgae_lite.viz._common import JOINT_NAMES, _numpy
from pgae_lite.world.words import CANONICAL, SIGNALS, SLOT_NAMES, SLOTS, VOCABULARY

#: One colour per signal, the same in every figure of the book.
SIGNAL_COLOURS: dict[str, str] = {
    "describe": "tab:blue", "execute": "tab:orange", "repeat action": "tab:green",
    "repeat both": "tab:purple", "repeat language": "tab:red"}


def plot_gates(gates_by_signal: Mapping[str, np.ndarray | torch.Tensor], title: str = "GMU gate z") -> Figure:
    """Mean GMU gate per signal (bars, ± one standard deviation) and per dimension (heat map).

    ``gates_by_signal`` maps a signal name to gate values of shape (N, hidden),
    e.g. ``{s: p.gate for s, p in predictions.items()}`` from
    :func:`pgae_lite.evaluate.table1.evaluate`. z near 1 lets the action features
    through, z near 0 the language features (h = z ⊙ A_h + (1 − z) ⊙ L_h).
    """
    names = list(gates_by_signal)
    gates = [_numpy(gates_by_signal[s]).reshape(-1, _numpy(gates_by_signal[s]).shape[-1]) for s in names]
    fig, (bars, heat) = plt.subplots(1, 2, figsize=(11, 0.5 * len(names) + 2.2),
                                     gridspec_kw={"width_ratios": [1, 2.2]})
    means = [g.mean() for g in gates]
    stds = [g.mean(1).std() for g in gates]                     # spread over samples
    y = np.arange(len(names))
    bars.barh(y, means, xerr=stds, color=[SIGNAL_COLOURS.get(s, "grey") for s in names])
    bars.axvline(0.5, color="black", lw=0.8, ls=":")
    bars.set(yticks=y, yticklabels=names, xlim=(0, 1), xlabel="mean z (0 = language, 1 = action)")
    bars.invert_yaxis()
    per_dim = np.stack([g.mean(0) for g in gates])              # (signals, hidden)
    im = heat.imshow(per_dim, aspect="auto", cmap="coolwarm", vmin=0, vmax=1, interpolation="nearest")
    heat.set(yticks=y, yticklabels=names, xlabel="dimension of h")
    fig.colorbar(im, ax=heat, label="mean z")
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_joints(pred: np.ndarray | torch.Tensor, target: np.ndarray | torch.Tensor,
                length: int | None = None, title: str = "", ax: plt.Axes | None = None) -> Figure:
    """The 5 joint angles over time: recorded (solid) and predicted (dashed).

    ``pred`` and ``target`` have shape (T, 5); steps at or past ``length`` (or
    NaN) are not drawn.
    """
    pred, target = _numpy(pred), _numpy(target)
    length = length or len(target)
    if ax is None:
        fig, ax = plt.subplots(figsize=(6, 3.2))
    else:
        fig = ax.figure
    steps = np.arange(length)
    for k in range(target.shape[1]):
        colour = f"C{k}"
        ax.plot(steps, target[:length, k], color=colour, lw=2, alpha=0.5, label=JOINT_NAMES[k])
        ax.plot(steps, pred[:length, k], color=colour, lw=1.2, ls="--")
    ax.plot([], [], color="grey", lw=2, alpha=0.5, label="recorded")
    ax.plot([], [], color="grey", lw=1.2, ls="--", label="predicted")
    ax.set(xlabel="time step", ylabel="joint value", title=title)
    ax.legend(fontsize="small", ncol=2, loc="best")
    fig.tight_layout()
    return fig


def plot_history(history: Sequence[Mapping]) -> Figure:
    """Training curves from ``Trained.history``: losses (log scale) and the mean gate per signal."""
    epochs = [r["epoch"] for r in history]
    fig, (loss_ax, gate_ax) = plt.subplots(1, 2, figsize=(11, 3.6))
    for key, label in (("loss", "total"), ("language_loss", "language (weighted CE)"),
                       ("action_loss", "action (MSE)")):
        loss_ax.plot(epochs, [r[key] for r in history], label=label, marker="." if len(epochs) < 10 else None)
    loss_ax.set(yscale="log", xlabel="epoch", ylabel="training loss", title="Loss")
    loss_ax.legend()
    for s in SIGNALS:
        points = [(r["epoch"], r["gate"][s]) for r in history if s in r["gate"]]
        if points:
            x, z = zip(*points)
            gate_ax.plot(x, z, label=s, color=SIGNAL_COLOURS[s], marker="." if len(x) < 10 else None)
    gate_ax.axhline(0.5, color="black", lw=0.8, ls=":")
    gate_ax.set(ylim=(0, 1), xlabel="epoch", ylabel="mean z", title="Mean GMU gate per signal (training)")
    gate_ax.legend(fontsize="small")
    for ax in (loss_ax, gate_ax):
        ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    fig.tight_layout()
    return fig


def _words(tokens: Sequence[int]) -> str:
    """Token indices of the 28-d input space -> text; signal tokens in brackets."""
    out = []
    for t in tokens:
        t = int(t)
        out.append(f"[{SIGNALS[t - len(VOCABULARY)]}]" if t >= len(VOCABULARY) else VOCABULARY[t])
    return " ".join(out)


def signal_table(batch: SignalBatch) -> pd.DataFrame:
    """One row per sample of ``batch``: what goes into the encoders and what the decoders must produce.

    Build ``batch`` with :func:`pgae_lite.model.signals.make_batch`, e.g. one sample
    under each of the five signals, to get the paper's "Signals" list as a table.
    """
    rows = []
    for i in range(len(batch.signal)):
        n_lang, n_act = int(batch.lang_lengths[i]), int(batch.action_lengths[i])
        steps = int(batch.joint_mask[i].sum()) + 1              # recorded steps of the sample
        target = batch.joint_target[i, :steps - 1]              # (steps-1, 5)
        held = bool(torch.allclose(target, batch.start_joints[i].expand_as(target)))
        first = batch.action_input[i, 0, -batch.start_joints.shape[1]:]
        if held:
            pose = "first" if torch.allclose(batch.start_joints[i], first) else "final"
            action_out = f"{pose} pose, held for {steps} steps"
        else:
            action_out = f"recorded sequence, {steps} steps"
        lang_out = _words(batch.lang_target[i][batch.lang_mask[i]].tolist()).replace(VOCABULARY[0], "<EOS>")
        rows.append({
            "signal": SIGNALS[int(batch.signal[i])],
            "language input": _words(batch.lang_tokens[i, :n_lang].tolist()).replace(VOCABULARY[0], "<EOS>"),
            "action input": f"whole sequence ({n_act} steps)" if n_act > 1 else "first step only",
            "language target": lang_out,
            "action target": action_out,
        })
    return pd.DataFrame(rows).set_index("signal")


def wrong_words(expected: str, generated: str) -> str:
    """Which of action / colour / speed differ ("" when none; synonyms count as equal).

    A generated text of another length than the expected one gives e.g. ``"2 words"``.
    """
    e, g = expected.split(), generated.split()
    if len(g) != len(e):
        return f"{len(g)} word{'s' * (len(g) != 1)}" if g else "<EOS> only"
    return ", ".join(n for n, a, b in zip(SLOT_NAMES, e, g) if CANONICAL[a] != CANONICAL.get(b))


def prediction_frame(pred, data: PGAEDataset) -> pd.DataFrame:
    """One row per sample of a :class:`pgae_lite.evaluate.table1.Predictions` on ``data`` (same order).

    Columns: id, code (the authors' label, e.g. ``PUSH-L-SLOW``), action, side,
    speed, arrangement, expected (the first of the 8 descriptions, or "" where
    the signal expects ``<EOS>`` alone), generated, correct, and wrong (which
    words of a wrong description are wrong). Group it for an error analysis,
    e.g. ``frame.groupby("action").correct.mean()``.
    """
    code = pd.Series(np.asarray(data.action), dtype=str)
    parts = code.str.split("-")
    says_words = pred.signal in ("describe", "repeat language", "repeat both")
    expected = [description_text(d[0]) if says_words else "" for d in data.descriptions]
    return pd.DataFrame({
        "id": np.asarray(data.ids),
        "code": code,
        "action": parts.str[0].str.lower(),
        "side": parts.str[1].map({"L": "left cube", "R": "right cube"}),
        "speed": parts.str[2].str.lower(),
        "arrangement": np.asarray(data.arrangement),
        "expected": expected,
        "generated": list(pred.text),
        "correct": np.asarray(pred.correct, dtype=bool),
        "wrong": ["" if ok else wrong_words(e, g) for ok, e, g in zip(pred.correct, expected, pred.text)],
    })


def plot_histories(histories: Mapping[str, Sequence[Mapping]],
                   keys: Sequence[str] = ("language_loss", "action_loss")) -> Figure:
    """Training curves of several runs on shared axes: one panel per loss, one line per run.

    ``histories`` maps a run's name to its ``Trained.history``, e.g.
    ``{"PGAE": pgae.history, "PGAE-BERT": bert.history}``; ``keys`` are the
    history's loss entries to draw (log scale).
    """
    titles = {"loss": "total loss", "language_loss": "language loss (weighted CE)", "action_loss": "action loss (MSE)"}
    fig, axes = plt.subplots(1, len(keys), figsize=(5.5 * len(keys), 3.4), squeeze=False)
    for ax, key in zip(axes[0], keys):
        for k, (name, history) in enumerate(histories.items()):
            epochs = [r["epoch"] for r in history]
            ax.plot(epochs, [r[key] for r in history], color=f"C{k}", label=name,
                    marker="." if len(epochs) < 10 else None)
        ax.set(yscale="log", xlabel="epoch", ylabel="training loss", title=titles.get(key, key))
        ax.xaxis.set_major_locator(MaxNLocator(integer=True))
        ax.legend(fontsize="small")
    fig.tight_layout()
    return fig


def plot_mean_gates(groups: Mapping[str, Mapping[str, np.ndarray | torch.Tensor]],
                    title: str = "Mean GMU gate per signal") -> Figure:
    """Mean GMU gate per signal for several models or views, as grouped bars (± one standard deviation).

    ``groups`` maps a group name (a model, a view) to ``{signal: gate values (N, hidden)}``,
    e.g. ``{"PGAE": {s: p.gate for s, p in preds.items()}, ...}``; a signal missing
    from a group leaves a gap. The spread is that of the per-sample mean gate.
    z near 1 lets the action features through, z near 0 the language features.
    """
    signals = list(dict.fromkeys(s for gates in groups.values() for s in gates))
    width = 0.8 / max(1, len(groups))
    fig, ax = plt.subplots(figsize=(1.6 * len(signals) + 3, 3.4))
    x = np.arange(len(signals))
    for k, (name, gates) in enumerate(groups.items()):
        per_sample = {s: _numpy(g).reshape(-1, _numpy(g).shape[-1]).mean(1) for s, g in gates.items()}
        means = [per_sample[s].mean() if s in per_sample else np.nan for s in signals]
        stds = [per_sample[s].std() if s in per_sample else 0.0 for s in signals]
        ax.bar(x + (k - (len(groups) - 1) / 2) * width, means, width, yerr=stds, label=name, color=f"C{k}",
               capsize=2)
    ax.axhline(0.5, color="black", lw=0.8, ls=":")
    ax.set(xticks=x, ylim=(0, 1), ylabel="mean z (0 = language, 1 = action)", title=title)
    ax.set_xticklabels(signals)
    ax.legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.0, 1.0))
    fig.tight_layout()
    return fig


def word_confusion(pred, data: PGAEDataset, slot: str = "action") -> pd.DataFrame:
    """Counts of expected (rows) against generated (columns) word at one position of a description.

    ``pred`` is a :class:`pgae_lite.evaluate.table1.Predictions` of a signal that outputs a
    description (``describe``, ``repeat language``) on ``data`` (same order); ``slot``
    is ``"action"``, ``"colour"`` or ``"speed"``. Words are counted as their canonical
    form (``move-up`` counts as ``push``). A generated text with too few words or a
    word that cannot stand at that position counts as ``"other"``.
    """
    k = SLOT_NAMES.index(slot)
    words = list(SLOTS[k])
    expected = [CANONICAL[VOCABULARY[int(d[0, k])]] for d in data.descriptions]
    generated = []
    for text in pred.text:
        parts = text.split()
        word = CANONICAL.get(parts[k]) if len(parts) > k else None
        generated.append(word if word in words else "other")
    table = pd.crosstab(pd.Categorical(expected, categories=words),
                        pd.Categorical(generated, categories=[*words, "other"]), dropna=False)
    table.index.name, table.columns.name = "expected", "generated"
    return table


def plot_word_confusion(preds: Mapping[str, object], data: PGAEDataset,
                        slots: Sequence[str] = SLOT_NAMES, title: str = "") -> Figure:
    """Confusion tables of :func:`word_confusion` as annotated heat maps: a row per entry, a column per slot.

    ``preds`` maps a label (a view, a model) to its ``Predictions`` on ``data``,
    e.g. ``{"NICO's view": self_preds["describe"], "opposite view": opp_preds["describe"]}``.
    Each row of a table is normalised to the fraction of its samples; the counts are written in the cells.
    """
    fig, axes = plt.subplots(len(preds), len(slots), squeeze=False,
                             figsize=(3.4 * len(slots) + 1, 2.9 * len(preds)),
                             gridspec_kw={"width_ratios": [3 + (s == "colour") * 3 for s in slots]})
    for r, (label, pred) in enumerate(preds.items()):
        for c, slot in enumerate(slots):
            table = word_confusion(pred, data, slot)
            counts = table.to_numpy()
            share = counts / np.maximum(counts.sum(1, keepdims=True), 1)
            ax = axes[r, c]
            ax.imshow(share, cmap="Blues", vmin=0, vmax=1, aspect="auto")
            for (i, j), n in np.ndenumerate(counts):
                if n:
                    ax.text(j, i, str(n), ha="center", va="center", fontsize=8,
                            color="white" if share[i, j] > 0.6 else "black")
            ax.set_xticks(range(counts.shape[1]), table.columns, rotation=45, ha="right", fontsize=8)
            ax.set_yticks(range(counts.shape[0]), table.index, fontsize=8)
            ax.set_title(f"{label}: {slot}" if label else slot, fontsize=9)
            if c == 0:
                ax.set_ylabel("expected")
            if r == len(preds) - 1:
                ax.set_xlabel("generated")
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig


__all__ = ["SIGNAL_COLOURS", "plot_gates", "plot_joints", "plot_history", "signal_table", "prediction_frame",
           "wrong_words", "plot_histories", "plot_mean_gates", "word_confusion", "plot_word_confusion"]
