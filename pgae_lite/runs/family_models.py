"""Chapter 09's own models: PRAE, PVAE and PTAE trained side by side on the profile's simulated data.

PGAE paper, Sec. 2 (PRAE, PVAE) and PTAE (Özdemir et al. 2023). PRAE and PVAE are trained by
:func:`pgae_lite.family.train.train_family`, PTAE by PGAE's loop through
:func:`~pgae_lite.runs.pipeline.trained_pgae` (cached like every PGAE). On a CPU the trainings are
units of one sweep (:func:`~pgae_lite.runs.sweep.run_sweep`), one core each; with a GPU, or one
worker, they train one after another here.

- ``"PRAE-8"``: PRAE reading all 8 equivalent descriptions of each action (the one-to-many
  experiment: its paper's data had one);
- ``"PVAE"``: PVAE as its authors train it;
- ``"PTAE"``: the ``"PTAE"`` training of :data:`pgae_lite.config.TRAININGS`.
"""
from __future__ import annotations

import os

from pgae_lite.config import TRAININGS, Profile, get_profile
from pgae_lite.family.train import FamilyTrained, family_recipe, train_family
from pgae_lite.runs.pipeline import _finished, simulated_dataset, trained_pgae
from pgae_lite.runs.sweep import run_sweep
from pgae_lite.util.storage import default_device

#: name -> (family model, all 8 descriptions?)
FAMILY_UNITS = {"PRAE-8": ("PRAE", True), "PVAE": ("PVAE", None)}


def _unit(name: str, profile: Profile, seed: int, device: str | None = None) -> FamilyTrained | float:
    """One training (on a sweep's worker: one thread): a family model (returned), or PTAE into the cache."""
    prof = get_profile(profile, seed=seed)
    if name == "PTAE":
        return trained_pgae("PTAE", prof, seed, device, progress=False).seconds
    model, every = FAMILY_UNITS[name]
    data = simulated_dataset(prof, device, progress=False)
    recipe = family_recipe(model, prof.train, prof.name, len(data.split("train")))
    return train_family(model, data, prof.model, recipe, device, all_descriptions=every)


def family_models(profile: Profile | str | None = None, seed: int = 0, device: str | None = None,
                  progress: bool = True, workers: int | None = None) -> dict:
    """``{"PRAE-8": FamilyTrained, "PVAE": FamilyTrained, "PTAE": Trained}`` for the profile and seed."""
    import torch

    prof = get_profile(profile)
    simulated_dataset(prof, device, progress)       # made once, before any worker reads it
    names = [*FAMILY_UNITS, *([] if _finished(TRAININGS["PTAE"], prof, seed) else ["PTAE"])]
    cpu = torch.device(device or default_device()).type == "cpu"
    workers = max(1, min(workers or os.cpu_count() or 1, len(names)))
    if progress:
        print(f"training {', '.join(names)}" + (f" side by side, {workers} at a time, one core each ..."
                                                  if cpu and workers > 1 else " ..."), flush=True)
    if cpu and workers > 1:
        done = run_sweep(_unit, [(n, prof, seed, "cpu") for n in names], workers=workers, name="family",
                         progress=False)
    else:
        done = [_unit(n, prof, seed, device) for n in names]
    out = {n: r for n, r in zip(names, done) if n != "PTAE"}
    out["PTAE"] = trained_pgae("PTAE", prof, seed, device, progress=False)
    return out


__all__ = ["FAMILY_UNITS", "family_models"]
