"""Chapter 09's own models: PRAE, PVAE and PTAE trained side by side on the profile's simulated data.

PGAE paper, Sec. 2 (PRAE, PVAE) and PTAE (Özdemir et al. 2023). PRAE and PVAE are trained by
:func:`pgae_lite.family.train.train_family` and cached beside the PGAEs
(:func:`~pgae_lite.runs.configured_unit.trained_configured`), PTAE by PGAE's loop through
:func:`~pgae_lite.runs.pipeline.trained_pgae`: a chapter run again loads them. On a CPU the trainings are
units of one sweep (:func:`~pgae_lite.runs.sweep.run_sweep`), one core each; with a GPU, or one
worker, they train one after another here.

- ``"PRAE-8"``: PRAE reading all 8 equivalent descriptions of each action (the one-to-many
  experiment: its paper's data had one);
- ``"PVAE"``: PVAE as its authors train it;
- ``"PTAE"``: the ``"PTAE"`` training of :data:`pgae_lite.config.TRAININGS`.
"""
from __future__ import annotations

import os
from pathlib import Path

from pgae_lite.config import TRAININGS, Profile, get_profile
from pgae_lite.family.train import TRAINING_VERSION, FamilyTrained
from pgae_lite.runs.configured_unit import SAVED, configured_profile, trained_configured
from pgae_lite.runs.pipeline import is_trained, model_folder, simulated_dataset, trained_pgae
from pgae_lite.runs.sweep import run_sweep
from pgae_lite.util.storage import default_device

#: name -> (family model, all 8 descriptions?)
FAMILY_UNITS = {"PRAE-8": ("PRAE", True), "PVAE": ("PVAE", None)}


def _saved_at(name: str, prof: Profile, seed: int, data) -> tuple[Profile, Path]:
    """The recipe of a family unit and where its model is cached: beside the PGAEs, under the data's, the
    CAE's and the recipe's digests, the unit's own name (PRAE-8 is not PRAE) and the training code's version."""
    prof = configured_profile(prof, FAMILY_UNITS[name][0], seed, len(data.split("train")))
    return prof, model_folder(prof, f"{name}-training{TRAINING_VERSION}") / SAVED


def _unit(name: str, profile: Profile, seed: int, device: str | None = None) -> FamilyTrained | float:
    """One training (on a sweep's worker: one thread), or a load: a family model, or PTAE into the cache."""
    prof = get_profile(profile, seed=seed)
    if name == "PTAE":
        return trained_pgae("PTAE", prof, seed, device, progress=False).seconds
    model, every = FAMILY_UNITS[name]
    data = simulated_dataset(prof, device, progress=False)
    prof, path = _saved_at(name, prof, seed, data)
    return trained_configured(path, model, prof, data, device, every)


def family_models(profile: Profile | str | None = None, seed: int = 0, device: str | None = None,
                  progress: bool = True, workers: int | None = None) -> dict:
    """``{"PRAE-8": FamilyTrained, "PVAE": FamilyTrained, "PTAE": Trained}`` for the profile and seed."""
    import torch

    prof = get_profile(profile)
    data = simulated_dataset(prof, device, progress)       # made once, before any worker reads it
    todo = [n for n in FAMILY_UNITS if not _saved_at(n, get_profile(prof, seed=seed), seed, data)[1].exists()]
    todo += [] if is_trained(TRAININGS["PTAE"], prof, seed) else ["PTAE"]
    cpu = torch.device(device or default_device()).type == "cpu"
    workers = max(1, min(workers or os.cpu_count() or 1, len(todo) or 1))
    if todo and progress:
        print(f"training {', '.join(todo)}" + (f" side by side, {workers} at a time, one core each ..."
                                                 if cpu and workers > 1 else " ..."), flush=True)
    if todo and cpu and workers > 1:
        run_sweep(_unit, [(n, prof, seed, "cpu") for n in todo], workers=workers, name="family", progress=False)
    out = {n: _unit(n, prof, seed, device) for n in FAMILY_UNITS}     # trained here, or loaded from the cache
    out["PTAE"] = trained_pgae("PTAE", prof, seed, device, progress=False)
    return out


__all__ = ["FAMILY_UNITS", "family_models"]
