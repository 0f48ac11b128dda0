"""The book's recipe against the paper's PGAE (Sec. 3 and 4): each departure and its measured effect.

One table for chapter 04 and the results page (appendix A2): what the paper (or the authors'
code) does, what the book's ``book`` profile does instead, why, and what the change did when
it was measured: read from a committed result file (:mod:`pgae_lite.runs.results`), or marked
"not measured" where no result file isolates it. The ``paper`` profile
(:data:`pgae_lite.config.PAPER`) takes every departure back; the history of how each was
found is the project's lab log (``experiments/HISTORY.md``), not the book.

    >>> departures_frame()          # one row per departure, for the page
"""
from __future__ import annotations

from dataclasses import dataclass
from statistics import median

import pandas as pd

from pgae_lite.runs import results

NOT_MEASURED = "not measured: no result file isolates it"


@dataclass(frozen=True)
class Departure:
    """One way the book's recipe departs from the paper, and where its effect was measured."""

    what: str
    paper: str
    book: str
    why: str
    #: ("ablation", ablation, result file, ...), ("plan head",), ("scaling", scaling), ("budget",),
    #: or None when nothing measured it
    evidence: tuple | None = None
    #: the profile fields (``model.cell``, ``train.lr``, ...) in which the ``paper`` profile takes it back
    fields: tuple[str, ...] = ()


DEPARTURES: tuple[Departure, ...] = (
    Departure("LSTM cell", "peephole LSTM", "fused nn.LSTM, no peepholes",
              "several times faster on a CPU",
              ("ablation", "cells", "ablations-cells"), ("model.cell",)),
    Departure("training budget",
              "6,000 epochs of 6, Adam 1e-5 constant, β = 1, one LSTM step per time step",
              "300 epochs of 16, AdamW 3e-3 with warm-up and cosine decay, β = 4, "
              "one LSTM step per three time steps",
              "a training in minutes on a CPU, not days",
              ("budget",), ("train.epochs", "train.batch_size", "train.lr", "train.schedule",
                            "train.warmup", "train.action_weight", "model.time_stride",
                            "train.checkpoint_every")),
    Departure("weight decay", "none", "0.1 (AdamW)",
              "smaller weights favour one rule for every action over a table per action",
              None, ("train.weight_decay",)),
    Departure("gradient clipping", "none", "norm 1",
              "no early step blows the weights up",
              None, ("train.clip",)),
    Departure("signals", "one per batch", "one per sample",
              "every batch trains every task",
              ("ablation", "per-batch", "ablations"), ("train.signals_per_sample",)),
    Departure("batches", "samples of any length", "samples of one length",
              "less padding: less time per epoch",
              None, ("train.length_batches",)),
    Departure("language decoder in training", "feeds back its own softmax", "teacher forcing",
              "all four steps in one fused pass",
              None, ("train.teacher_language",)),
    Departure("action decoder reads", "its own last prediction", "the start joints",
              "its errors cannot feed back and grow; all steps in one fused pass",
              None, ("model.joint_feedback",)),
    Departure("language LSTMs' input weights", "U(-0.1, 0.1)", "N(0, 1), like a word embedding",
              "kept from an earlier, slower recipe, where the authors' small weights left the words on a "
              "plateau; today's recipe gains no word accuracy from it (the measured effect)",
              ("ablation", "embedding", "ablations", "ablations-short")),
    Departure("GMU", "no normalisation", "layer norm of W_A f_act + b",
              "on some seeds the action's cell states saturated the candidate and describe never learnt",
              None, ("model.gmu_norm",)),
    Departure("plan head", "none", "10 keyframes predicted from h in training (γ = 4)",
              "h must say which cube will move: the closed loop needs it",
              ("plan head",), ("model.plan_keyframes", "train.plan_weight")),
    Departure("input noise", "none", "std 0.1 on the visual features, 0.05 on the joints",
              "the encoder cannot memorise the 108 training patterns",
              None, ("train.input_noise", "train.joint_input_noise")),
    Departure("visual features", "one minimum and maximum over all 30 (each view its own)",
              "whitened first, then one minimum and maximum",
              "every direction of the features gets a similar spread (chapter 04 measures the spectrum)",
              ("scaling", "global", "the authors' scaling"), ("train.vision_scaling",)),
    Departure("the opposite view's scale", "its own minimum and maximum", "NICO's view's (one scale)",
              "one picture, one set of numbers",
              ("scaling", "whiten-per-view", "each view its own scale, whitened")),
    Departure("scaling statistics", "train and test split", "training split only",
              "the test split stays unseen"),
)


def _ablation(ablation: str, *names: str) -> str:
    said = []
    for name in names:
        budget = results.value(name).get("epochs")
        when = f"in {budget} epochs, " if budget else ""
        frame = results.ablation_frame(ablation, name)
        runs = results.value(name, "runs")
        seconds = {who: median([r["train_seconds"] for r in runs if r["ablation"] == who])
                   for who in ("recipe", ablation)}
        said.append(f"{when}{results.ablation_verdict(frame)}, a training {seconds[ablation] / seconds['recipe']:.2f} "
                    f"times as long ({name}.json)")
    return "with the paper's choice: " + "; ".join(said)


def _plan_head() -> str:
    runs = results.value("closed_loop", "runs")
    closed = {t: median([r["closed_success_%"] for r in runs if r["training"] == t])
              for t in ("PGAE", "PGAE-no-plan")}
    return (f"closed loop {closed['PGAE']:.1f}% with it, {closed['PGAE-no-plan']:.1f}% without "
            f"(median of {len(runs) // 3} seeds; closed_loop.json)")


def scaling_cells(dataset: str) -> dict[str, dict[str, float]]:
    """``opposite_scale-DATASET``: per scaling, the medians over seeds of describe (both views)."""
    runs = results.value(f"opposite_scale-{dataset}", "runs")
    cells = {}
    for scaling in dict.fromkeys(r["scaling"] for r in runs):
        mine = [r for r in runs if r["scaling"] == scaling]
        cells[scaling] = {view: median([r["table1"][view]["describe"]["accuracy"] for r in mine])
                          for view in ("self", "opposite")}
        cells[scaling]["seeds"] = len(mine)
    return cells


def _scaling(scaling: str, label: str) -> str:
    said = []
    for dataset, called in (("original", "authors' data"), ("ours", "our data")):
        name = f"opposite_scale-{dataset}"
        cells = scaling_cells(dataset) if name in results.names() else {}
        if "whiten" in cells and scaling in cells:
            book, paper = cells["whiten"], cells[scaling]
            said.append(f"{called}, {book['self']:.1f} / {book['opposite']:.1f}% with the book's, "
                        f"{paper['self']:.1f} / {paper['opposite']:.1f}% with {label} "
                        f"({paper['seeds']} seeds; {name}.json)")
    if not said:
        return NOT_MEASURED
    return "two-view model, describe self / opposite (medians): " + "; ".join(said)


def _budget() -> str:
    rows = {r["recipe"]: r for r in results.value("recipe_time", "rows")}
    old, new = rows["previous"], rows["book"]
    return (f"{old['seconds'] / 60:.1f} → {new['seconds'] / 60:.1f} min a training against the recipe before "
            f"this one ({old['epochs']} epochs of {old['batch_size']}, one step per time step), describe "
            f"{old['cells']['describe']['accuracy']:.1f} → {new['cells']['describe']['accuracy']:.1f}%, execute "
            f"nRMSE {old['cells']['execute']['nrmse']:.3f} → {new['cells']['execute']['nrmse']:.3f}% (authors' "
            "data, seed 0; recipe_time.json); the paper's 6,000 epochs were never run on a CPU")


def measured_effect(departure: Departure) -> str:
    """What the departure did, in one sentence from its result file, or ``NOT_MEASURED``."""
    if departure.evidence is None:
        return NOT_MEASURED
    kind, *args = departure.evidence
    effects = {"ablation": _ablation, "plan head": _plan_head, "scaling": _scaling, "budget": _budget}
    return effects[kind](*args)


def departures_frame() -> pd.DataFrame:
    """Every departure as a row: the paper's way, the book's, why, and the measured effect."""
    return pd.DataFrame([{"departure": d.what, "the paper": d.paper, "the book": d.book, "why": d.why,
                          "measured effect": measured_effect(d)} for d in DEPARTURES]).set_index("departure")


__all__ = ["DEPARTURES", "Departure", "NOT_MEASURED", "departures_frame", "measured_effect", "scaling_cells"]
