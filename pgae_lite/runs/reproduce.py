"""Reproducing Table 1: train the rows' models, evaluate them, print them beside the paper's.

Paper, Sec. 4 and Table 1. Table 1's four rows come from three trainings, and the family's rows
(PRAE, PVAE, PVAE-BERT(-tuned), PTAE) stand beside them (:mod:`pgae_lite.runs.rows`: how each is
built, trained and measured). ``execute`` and ``repeat language`` show no action to the encoder
beyond the first step, so PGAE-opposite shares those two cells with PGAE-self (as in the paper).
A cell a model has no path for (PRAE's and PVAE's configurations) is N.A., ``null``. With several
seeds every cell is reported as mean ± standard deviation.

Output folder layout (``out``)::

    results.json                 every cell of every row and seed, mean and std, times
                                 (strict JSON: a NaN or an infinity is written as null)
    predictions.npz              the first row's predictions for the first seed
    TRAINING-seedS/checkpoint.pt one folder per training and seed (resumable)
    TRAINING-seedS/predictions-ROW.npz
    logs/table1-K.log            each unit's output, when the units ran as a sweep

Each (training, seed) is one unit (:mod:`pgae_lite.runs.table1_unit`); several run side by
side on this machine's cores, or on a Dask cluster (:mod:`pgae_lite.runs.sweep`).
"""
from __future__ import annotations

import json
import math
import os
import statistics
import time
from pathlib import Path

import numpy as np

from pgae_lite.bert.pretrained import model_source
from pgae_lite.config import Profile, get_profile
from pgae_lite.data.dataset import PGAEDataset
from pgae_lite.evaluate.table1 import Predictions, format_table
from pgae_lite.runs.data import data_source, loaded, remember
from pgae_lite.runs.rows import ROWS, TABLE1_ROWS
from pgae_lite.runs.scheduler import connect, disconnect, scheduler_address
from pgae_lite.runs.sweep import run_sweep
from pgae_lite.runs.table1_unit import check_made_on, table1_unit
from pgae_lite.util.checks import MAX_SEED, instance_of, torch_device, whole_number
from pgae_lite.util.errors import ArgumentError
from pgae_lite.util.storage import atomic_write, atomic_write_text, default_device, make_folder
from pgae_lite.world.words import TEST_SIGNALS

CELLS = ("accuracy", "nrmse", "nrmse_padded")
#: What :func:`reproduce` writes into its folder (the layout above): a folder holding only these is one it wrote.
WRITES = ("results.json", "predictions.npz", "*-seed*", "logs")
MAX_SEEDS = 100                                     # models per row: a sane count
#: The command line's name of each argument :func:`check_arguments` checks.
FLAGS = {"original_data": "--original-data", "rows": "--rows", "seed": "--seed",
         "seeds": "--seeds", "epochs": "--epochs", "device": "--device",
         "pretrained_model": "--pretrained-model", "out_dir": "--out", "workers": "--workers",
         "scheduler": "--scheduler"}


def parse_rows(rows: str | list[str] | tuple[str, ...] | None) -> list[str]:
    """``"all"``, a comma-separated string or a list of row names -> checked list (case-insensitive)."""
    if rows is None:
        return ["PGAE"]
    instance_of("rows", rows, (str, list, tuple), "'all', a list or names and commas")
    if isinstance(rows, str):
        rows = list(TABLE1_ROWS) if rows.strip().lower() == "all" else rows.split(",")
    if not rows:
        raise ArgumentError(f"rows is empty; the rows are: {', '.join(ROWS)} or 'all'")
    by_lower = {r.lower(): r for r in ROWS}
    out = []
    for r in rows:
        name = by_lower.get(r.strip().lower()) if isinstance(r, str) else None
        if name is None:
            shown = r.strip() if isinstance(r, str) else r
            raise ArgumentError(f"unknown row {shown!r}; the rows are: "
                                f"{', '.join(ROWS)} (or 'all': Table 1's)")
        if name not in out:
            out.append(name)
    return out


def check_arguments(original_data, rows, seed, seeds, epochs, device, pretrained_model,
                    out_dir, workers=None, scheduler=None, cli: bool = False) -> list[str]:
    """:func:`reproduce`'s arguments checked before any data is read; returns the rows.

    A bad one raises a one-sentence :class:`~pgae_lite.util.errors.PGAELiteError` that
    names it as the command line does (:data:`FLAGS`) if ``cli``.
    """
    name = FLAGS if cli else {key: key for key in FLAGS}
    rows = parse_rows(rows)
    whole_number(name["seed"], seed, 0, MAX_SEED)
    whole_number(name["seeds"], seeds, 1, MAX_SEEDS)
    if seed + seeds - 1 > MAX_SEED:
        raise ArgumentError(f"{name['seed']} {seed} with {name['seeds']} {seeds} "
                            f"reaches seed {seed + seeds - 1}; seeds go up to "
                            f"2**32 - 1 = {MAX_SEED}")
    if epochs is not None:
        whole_number(name["epochs"], epochs, 1)
    if workers is not None:
        whole_number(name["workers"], workers, 1)
    scheduler_address(scheduler, name["scheduler"])     # or $PGAE_DASK_SCHEDULER: a Dask scheduler's address
    torch_device(name["device"], device)
    defaults = {"original_data": "our simulated data",
                "out_dir": "runs/DATA-PROFILE-seedSEED"}
    for key, value in (("original_data", original_data), ("out_dir", out_dir)):
        instance_of(name[key], value, (str, os.PathLike), "a folder (str or Path)",
                    optional=True)
        if value is not None and not str(value).strip():
            raise ArgumentError(f"{name[key]} is empty (an unset variable?); give a "
                                f"folder, or leave {name[key]} out for the default: "
                                f"{defaults[key]}")
    pretrained = [r for r in rows if "language" in ROWS[r].training.model]    # a pretrained language encoder
    if pretrained:
        model_source(pretrained_model)     # a missing model: refused before any data
    elif pretrained_model is not None:
        raise ArgumentError(f"{name['pretrained_model']} {pretrained_model!r} is the "
                            f"pretrained language model of PGAE-BERT and PVAE-BERT, but no row "
                            f"({', '.join(rows)}) reads it; add one to "
                            f"{name['rows']} or leave {name['pretrained_model']} out")
    return rows


def finite_or_null(obj) -> tuple[object, int]:
    """``obj`` with each NaN or infinity replaced by None (JSON's null); their count."""
    if isinstance(obj, float):
        return (obj, 0) if math.isfinite(obj) else (None, 1)
    if isinstance(obj, (dict, list, tuple)):
        keys = list(obj) if isinstance(obj, dict) else range(len(obj))
        pairs = [finite_or_null(obj[k]) for k in keys]
        values = [v for v, _ in pairs]
        clean = dict(zip(keys, values)) if isinstance(obj, dict) else values
        return clean, sum(n for _, n in pairs)
    return obj, 0


def write_results(path: Path, report: dict) -> int:
    """``report`` as strict JSON (NaN, infinities as null), atomically; their count."""
    clean, nonfinite = finite_or_null(report)
    atomic_write_text(path, json.dumps(clean, indent=2, allow_nan=False))
    return nonfinite


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


def summarise(per_seed: list[dict[str, dict[str, float | None]]]) -> tuple[dict, dict]:
    """Mean and standard deviation (0 for one seed) of every cell over seeds; None where a cell is N.A."""
    def over(s: str, c: str, f) -> float | None:
        values = [r[s][c] for r in per_seed]
        return None if any(v is None for v in values) else f(values)
    mean = {s: {c: over(s, c, statistics.fmean) for c in CELLS} for s in TEST_SIGNALS}
    std = {s: {c: over(s, c, lambda v: statistics.stdev(v) if len(v) > 1 else 0.0) for c in CELLS}
           for s in TEST_SIGNALS}
    return mean, std


def run_table1(dataset: PGAEDataset, rows: list[str], seeds: list[int], out: Path,
               profile: Profile, device: str | None = None, progress: bool = True,
               pretrained_model: str | None = None, original_data: str | Path | None = None,
               workers: int | None = None, scheduler: str | None = None, client=None) -> dict:
    """Train (or resume) every training the ``rows`` need, for every seed; evaluate; write ``out``.

    Each (training, seed) is one unit (:func:`~pgae_lite.runs.table1_unit.table1_unit`). On the CPU
    with more than one unit they run as a sweep (:func:`~pgae_lite.runs.sweep.run_sweep`): ``workers``
    single-threaded processes here (default: one per core, at most one per unit), or the Dask
    cluster at ``scheduler`` (or ``$PGAE_DASK_SCHEDULER``), whose workers read ``original_data``
    at the same path, or make this profile's simulated data in their own cache; ``client``: a client
    already connected to it (:func:`~pgae_lite.runs.scheduler.connect`). Else, or with ``workers=1``,
    one after another in this process. Every unit's model is checked against ``dataset``
    (:func:`~pgae_lite.runs.table1_unit.check_made_on`). A scheduler lost in the middle of the sweep
    is one sentence that names what is saved in ``out`` and how to resume.
    """
    dataset.split("train"), dataset.split("test")    # both needed: refused now, not after the trainings
    make_folder(out)                 # a file in the way, or no permission: one sentence
    source = None if original_data is None else str(Path(original_data).resolve())
    trainings = list({ROWS[r].training.name: ROWS[r].training for r in rows}.values())
    units = [(source, profile, t, seed, [ROWS[r] for r in rows if ROWS[r].training == t], str(Path(out).resolve()),
              device, pretrained_model) for t in trainings for seed in seeds]
    if client is not None or _as_sweep(len(units), device, workers, scheduler):
        folders = [f"{t.name}-seed{seed}" for t in trainings for seed in seeds]
        shown = ", ".join(folders[:3]) + (f" and {len(folders) - 3} more" if len(folders) > 3 else "")
        saved = (f"each training finished or checkpointed so far is saved in {out} ({shown}: checkpoint.pt); run "
                 f"the same command again with the same output folder, on the scheduler restarted or here without "
                 f"one, to resume from them")
        done = run_sweep(table1_unit, units, workers=min(workers or os.cpu_count() or 1, len(units)),
                         scheduler=scheduler, logs=Path(out) / "logs", name="table1", progress=progress,
                         client=client, on_lost=saved)
    else:
        remember(data_source(original_data, profile), dataset)
        done = [table1_unit(*unit, progress=progress) for unit in units]
    report = {"data": dataset.source, "profile": profile.name, "seeds": seeds, "rows": {}, "trainings": {}}
    for row in rows:
        paper = ROWS[row].paper                                # None: not a row of the paper's Table 1
        report["rows"][row] = {"training": ROWS[row].training.name, "paper": None if paper is None else {
            s: {"accuracy": a, "nrmse": e} for s, (a, e) in paper.items()}, "seeds": {}}
    for unit in done:
        folder = out / f"{unit['training']}-seed{unit['seed']}"
        check_made_on(unit, dataset, folder)          # trained elsewhere on other features: an error
        info = report["trainings"].setdefault(unit["training"], {"profile": unit["profile"], "train_seconds": {}})
        info["train_seconds"][str(unit["seed"])] = unit["seconds"]
        for row, cells in unit["cells"].items():
            make_folder(folder)
            save_predictions(folder / f"predictions-{row}.npz", unit["predictions"][row])
            report["rows"][row]["seeds"][str(unit["seed"])] = cells
    for row in rows:
        mean, std = summarise([report["rows"][row]["seeds"][str(s)] for s in seeds])
        report["rows"][row] |= {"mean": mean, "std": std}
    first = next(u for u in done if u["training"] == ROWS[rows[0]].training.name and u["seed"] == seeds[0])
    save_predictions(out / "predictions.npz", first["predictions"][rows[0]])
    return report


def _as_sweep(units: int, device: str | None, workers: int | None, scheduler: str | None) -> bool:
    """Whether :func:`run_table1` runs its units as a sweep: on a given cluster always; here, on the
    CPU with more than one unit and more than one worker (a GPU trains one model at a time)."""
    if scheduler_address(scheduler) is not None:
        return True
    import torch

    cpu = torch.device(device or default_device()).type == "cpu"
    return cpu and units > 1 and (workers or os.cpu_count() or 1) > 1


def reproduce(original_data: str | Path | None = None, profile: str | None = None, seed: int = 0,
              out_dir: str | Path | None = None, epochs: int | None = None,
              device: str | None = None, progress: bool = True, rows: str | list[str] | None = None,
              seeds: int = 1, pretrained_model: str | None = None, workers: int | None = None,
              scheduler: str | None = None) -> dict:
    """Table 1 from scratch: train (or resume) and evaluate the chosen rows; write and print the results.

    ``original_data`` is the authors' data folder; ``None`` runs the whole pipeline on
    our simulated data (simulator -> CAE -> PGAE, each step cached). ``rows``: see
    :data:`pgae_lite.runs.rows.ROWS` (default ``["PGAE"]``, ``"all"`` for every row). ``seeds`` models
    per row are trained, with seeds ``seed, seed + 1, ...``: on the CPU, side by side on ``workers``
    cores (default: all), or on the Dask cluster at ``scheduler`` (:func:`run_table1`). Every
    argument is checked before any data is read (:func:`check_arguments`), and so is the cluster: the
    scheduler answers and a worker has joined (:func:`~pgae_lite.runs.scheduler.connect`).
    """
    rows = check_arguments(original_data, rows, seed, seeds, epochs, device,
                           pretrained_model, out_dir, workers, scheduler)
    prof = get_profile(profile, **({} if epochs is None else {"epochs": epochs}))
    named = scheduler_address(scheduler)             # the argument, else $PGAE_DASK_SCHEDULER, else None: here
    client = None if named is None else connect(named)      # nobody there, no worker: one sentence, no data read
    try:
        source = data_source(original_data, prof)    # the authors' folder, or this profile's simulated data
        dataset = loaded(source, device, progress)
        default_out = f"runs/{source.kind}-{prof.name}-seed{seed}"
        out = Path(out_dir if out_dir is not None else default_out)
        t0 = time.perf_counter()
        report = run_table1(dataset, rows, list(range(seed, seed + seeds)), out, prof, device, progress,
                            pretrained_model, original_data, workers, scheduler, client)
    finally:
        if client is not None:
            disconnect(client)
    report |= {"data": dataset.source if original_data is None else str(original_data),
               "wall_seconds": time.perf_counter() - t0}
    nonfinite = write_results(out / "results.json", report)
    print(format_table({f"{r} (ours)": report["rows"][r]["mean"] for r in rows},
                       {f"{r} (ours)": r for r in rows if ROWS[r].paper is not None},
                       std={f"{r} (ours)": report["rows"][r]["std"] for r in rows} if seeds > 1 else None))
    times = ", ".join(f"{t} {statistics.fmean(v['train_seconds'].values()):.0f} s"
                      for t, v in report["trainings"].items())
    print(f"\nprofile {prof.name}, seeds {report['seeds']}, mean training time: {times}; "
          f"wrote {out / 'results.json'} and {out / 'predictions.npz'}")
    if nonfinite:
        print(f"note: {nonfinite} value(s) were not finite (NaN or infinite); "
              "results.json holds null there")
    return report


__all__ = ["FLAGS", "MAX_SEEDS", "check_arguments", "finite_or_null", "parse_rows",
           "reproduce", "run_table1", "save_predictions", "summarise", "write_results"]
