"""Reproducing Table 1: train the rows' models, evaluate them, print them beside the paper's.

Paper, Sec. 4 and Table 1. Four rows come from three trainings::

    | row           | training                                   | evaluated on                  |
    |---------------|--------------------------------------------|-------------------------------|
    | PGAE          | LSTM language encoder, NICO's view only     | NICO's own actions            |
    | PGAE-BERT     | frozen pretrained language encoder          | NICO's own actions            |
    | PGAE-self     | NICO's or the opposite agent's view, 50/50  | NICO's own actions            |
    | PGAE-opposite | the same model as PGAE-self                 | the opposite agent's actions  |

``execute`` and ``repeat language`` show no action to the encoder beyond the
first step, so PGAE-opposite shares those two cells with PGAE-self (as in the
paper). With several seeds every cell is reported as mean ± standard deviation.

Output folder layout (``out``)::

    results.json                 every cell of every row and seed, mean and std, times
    predictions.npz              the first row's predictions for the first seed
    TRAINING-seedS/checkpoint.pt one folder per training and seed (resumable)
    TRAINING-seedS/predictions-ROW.npz
"""
from __future__ import annotations

import json
import shutil
import statistics
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from .config import ROWS, TRAININGS, Profile, get_profile, training_profile  # TRAININGS: the README names it here
from .data import PGAEDataset
from .evaluate import PAPER_TABLE, Predictions, evaluate, format_table
from .language import TEST_SIGNALS
from .train import train
from .utils import atomic_write


SHARED_WITH_SELF = ("execute", "repeat language")   # no action shown: the opposite view changes nothing
CELLS = ("accuracy", "nrmse", "nrmse_padded")


def parse_rows(rows: str | list[str] | tuple[str, ...] | None) -> list[str]:
    """``"all"``, a comma-separated string or a list of row names -> checked list (case-insensitive)."""
    if rows is None:
        return ["PGAE"]
    if isinstance(rows, str):
        rows = list(ROWS) if rows.strip().lower() == "all" else rows.split(",")
    by_lower = {r.lower(): r for r in ROWS}
    out = []
    for r in rows:
        name = by_lower.get(r.strip().lower())
        if name is None:
            raise ValueError(f"unknown row {r.strip()!r}; the rows are: {', '.join(ROWS)} (or 'all')")
        if name not in out:
            out.append(name)
    return out


def save_predictions(path: Path, preds: dict[str, Predictions]) -> None:
    """``S_ids``, ``S_text``, ``S_joints`` for each test signal S (spaces as ``_``), written atomically."""
    arrays = {}
    for signal, p in preds.items():
        key = signal.replace(" ", "_")
        arrays[f"{key}_ids"] = p.ids.astype(str)
        arrays[f"{key}_text"] = np.asarray(p.text, dtype=str)
        arrays[f"{key}_joints"] = p.joints
    with atomic_write(path) as f:
        np.savez_compressed(f, **arrays)


def summarise(per_seed: list[dict[str, dict[str, float]]]) -> tuple[dict, dict]:
    """Mean and standard deviation (0 for one seed) of every cell over seeds."""
    mean = {s: {c: statistics.fmean(r[s][c] for r in per_seed) for c in CELLS} for s in TEST_SIGNALS}
    std = {s: {c: statistics.stdev([r[s][c] for r in per_seed]) if len(per_seed) > 1 else 0.0 for c in CELLS}
           for s in TEST_SIGNALS}
    return mean, std


def run_table1(dataset: PGAEDataset, rows: list[str], seeds: list[int], out: Path,
               profile: Profile, device: str | None = None, progress: bool = True,
               pretrained_model: str | None = None) -> dict:
    """Train (or resume) every training the ``rows`` need, for every seed; evaluate; write ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    report = {"data": dataset.source, "profile": profile.name, "seeds": seeds, "rows": {}, "trainings": {}}
    for row in rows:
        report["rows"][row] = {"training": ROWS[row][0], "paper": {
            s: {"accuracy": a, "nrmse": e} for s, (a, e) in PAPER_TABLE[row].items()}, "seeds": {}}
    for training in dict.fromkeys(ROWS[r][0] for r in rows):
        for seed in seeds:
            prof = training_profile(replace(profile, train=replace(profile.train, seed=seed)), training,
                                    pretrained_model)
            folder = out / f"{training}-seed{seed}"
            trained = train(dataset, prof, out_dir=folder, device=device, progress=progress)
            info = report["trainings"].setdefault(training, {"profile": prof.to_dict(), "train_seconds": {}})
            info["train_seconds"][str(seed)] = trained.seconds
            self_results = None
            for row in (r for r in rows if ROWS[r][0] == training):
                opposite = ROWS[row][1]
                results, preds = evaluate(trained.model, dataset, trained.normaliser, opposite=opposite)
                if opposite:
                    if self_results is None:
                        self_results, _ = evaluate(trained.model, dataset, trained.normaliser)
                    results |= {s: self_results[s] for s in SHARED_WITH_SELF}
                else:
                    self_results = results
                save_predictions(folder / f"predictions-{row}.npz", preds)
                report["rows"][row]["seeds"][str(seed)] = results
    for row in rows:
        mean, std = summarise([report["rows"][row]["seeds"][str(s)] for s in seeds])
        report["rows"][row] |= {"mean": mean, "std": std}
    first = out / f"{ROWS[rows[0]][0]}-seed{seeds[0]}" / f"predictions-{rows[0]}.npz"
    shutil.copyfile(first, out / "predictions.npz")
    return report


def reproduce(original_data: str | Path | None = None, profile: str | None = None, seed: int = 0,
              out_dir: str | Path | None = None, epochs: int | None = None,
              device: str | None = None, progress: bool = True, rows: str | list[str] | None = None,
              seeds: int = 1, pretrained_model: str | None = None) -> dict:
    """Table 1 from scratch: train (or resume) and evaluate the chosen rows; write and print the results.

    ``original_data`` is the authors' data folder; ``None`` runs the whole pipeline on
    our simulated data (simulator -> CAE -> PGAE, each step cached). ``rows``: see
    :data:`pgae_lite.config.ROWS` (default ``["PGAE"]``, ``"all"`` for every row). ``seeds`` models
    per row are trained, with seeds ``seed, seed + 1, ...``.
    """
    from .original import load_original

    rows = parse_rows(rows)
    if seeds < 1:
        raise ValueError(f"seeds must be at least 1, got {seeds}")
    prof = get_profile(profile, **({"epochs": epochs} if epochs else {}))
    if original_data:
        dataset, source = load_original(original_data), "original"
    else:
        from .pipeline import simulated_dataset
        dataset, source = simulated_dataset(prof.name, device, progress), "simulated"
    out = Path(out_dir or f"runs/{source}-{prof.name}-seed{seed}")
    t0 = time.perf_counter()
    report = run_table1(dataset, rows, list(range(seed, seed + seeds)), out, prof, device, progress,
                        pretrained_model)
    report |= {"data": str(original_data) if original_data else dataset.source,
               "wall_seconds": time.perf_counter() - t0}
    (out / "results.json").write_text(json.dumps(report, indent=2))
    print(format_table({f"{r} (ours)": report["rows"][r]["mean"] for r in rows},
                       {f"{r} (ours)": r for r in rows},
                       std={f"{r} (ours)": report["rows"][r]["std"] for r in rows} if seeds > 1 else None))
    times = ", ".join(f"{t} {statistics.fmean(v['train_seconds'].values()):.0f} s"
                      for t, v in report["trainings"].items())
    print(f"\nprofile {prof.name}, seeds {report['seeds']}, mean training time: {times}; "
          f"wrote {out / 'results.json'} and {out / 'predictions.npz'}")
    return report


__all__ = ["reproduce", "run_table1", "parse_rows", "save_predictions", "summarise"]
