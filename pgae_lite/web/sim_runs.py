"""The simulator's own runs for chapter 08's page, made when the book is built (not in the paper).

Paper, Sec. 4 (the "execute" task), here closed loop (:mod:`pgae_lite.robot.closedloop`, chapter 07):
the model reads, every ``time_stride`` steps, NICO's view of its own motion. The paper has no such
runs; the closed loop is ours. The reader's browser runs the models (ONNX, :mod:`pgae_lite.web.assets`)
but not the physics, so what needs the simulator, the cube actually moving, is shown from these runs,
labelled as runs of the simulator at build time. :func:`simulator_runs` writes ``sim_runs.json``::

    {"label": ..., "profile": ..., "seed": ...,
     "runs": [{"model", "episode", "signal": "execute", "kind": "closed loop", "description", "passed",
               "joints":   (T, 5)     the joints the model wrote (data units, Execution.joints),
               "measured": (T, 5)     the simulator's measured joints,
               "cubes":    (T, 2, 3)  left and right cube centres after each step (m, world frame)}]}

Which episodes: the first test episode of each pattern, in the test split's order (the manifest's),
so every scene and action of the split is there once: 36 patterns in the book and paper profiles,
10 in smoke. One run is ~2 ms per step on a CPU core (rendering 120 x 160 and the CAE), 0.1 s for a
fast episode and 0.2 s for a slow one: 3 models x 36 episodes ~ 20 s. Same seed, same file.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from tqdm.auto import tqdm

from pgae_lite.data.dataset import PGAEDataset, description_text
from pgae_lite.robot.closedloop import closed_loop, variation_of
from pgae_lite.runs.data import SimulatedData, loaded, trained_cae
from pgae_lite.util.storage import atomic_write_text, make_folder

LABEL = ("Run in the pybullet simulator when this book was built, closed loop: "
         "the model saw its own motion.")
#: Decimals kept in the file: 10 µm for the cubes, 1e-5 rad for the joints.
DECIMALS = 5


def chosen_episodes(test: PGAEDataset) -> list[int]:
    """Rows of ``test``: the first episode of each pattern, in the split's order."""
    seen, rows = set(), []
    for i, pattern in enumerate(test.pattern.tolist()):
        if pattern not in seen:
            seen.add(pattern)
            rows.append(i)
    return rows


def _values(array: np.ndarray) -> list:
    """A float array as nested lists, rounded to :data:`DECIMALS`."""
    return np.round(np.asarray(array, dtype=np.float64), DECIMALS).tolist()


def simulator_runs(out: str | Path, trained: dict, source: SimulatedData, label: dict, progress: bool = False) -> dict:
    """Run every model of ``trained`` (the page's name -> its trained model, :func:`~pgae_lite.web.assets.export_web`'s)
    closed loop on :func:`chosen_episodes` of ``source``'s test split, with NICO's eye, its CAE, in the scenes its
    profile records; write ``out/sim_runs.json`` (see the module docstring, with ``label``'s profile and seed)
    and return its content. The CAE and the data come from the cache (made there when missing)."""
    out = make_folder(out)
    test = loaded(source, "cpu", progress).split("test")
    cae, _ = trained_cae(source.profile, "cpu", progress=progress)        # NICO's eye: frame -> 30 features
    config = source.profile.data
    rows = chosen_episodes(test)
    runs = []
    for name, run_of in trained.items():
        model = run_of.model.cpu().eval()
        for i in tqdm(rows, desc=f"{name}, closed loop", unit="ep", disable=not progress):
            said = description_text(test.descriptions[i, 0])        # the manifest's description
            run = closed_loop(model, cae, run_of.normaliser, int(test.pattern[i]), variation_of(test.ids[i]),
                              said, config=config)
            runs.append({"model": name, "episode": str(test.ids[i]), "signal": "execute", "kind": "closed loop",
                         "description": said, "passed": bool(run.passed),
                         "joints": _values(run.joints),             # (T, 5)
                         "measured": _values(run.measured),         # (T, 5)
                         "cubes": _values(run.cubes)})              # (T, 2, 3)
    result = {"label": LABEL, **label, "runs": runs}
    atomic_write_text(out / "sim_runs.json", json.dumps(result))
    return result


__all__ = ["simulator_runs", "chosen_episodes", "LABEL"]
