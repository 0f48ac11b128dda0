"""What the live playground reads in the page, written at build time (not in the paper).

Paper, Sec. 3 and 4: the models of chapter 08's playground and the episodes they run on.
:func:`export_web` writes, from the cache (no retraining when the chapters trained them)::

    models/NAME.onnx      each model's :class:`~pgae_lite.web.export.EpisodeGraph`
    models/NAME.table     PGAE-BERT only: its features of the 581 fixed inputs the playground's signals
                          read (all but repeat both's), float32 (581, D),
                          row ``manifest["fixed_rows"]["s,w1,w2,w3,eos"]`` for those tokens
    (free text)           PGAE-BERT's sentence encoder, word table and refusals (free_text.py)
    sim_runs.json         the simulator's closed-loop runs at build time (sim_runs.py), labelled so
    frames/PPP-V-first.png, frames/PPP-V-last.png
                          NICO's camera in each episode's recording, at its first and last step
                          (what the CAE read; the page shows them for the chosen episode)
    episodes.bin          every test episode, normalised as the model reads it, float32:
                          action input (T, 35): [v_t; j_t] per step (episodes.py)
    episodes-train.bin    the same for the first recording of each training pattern (fetched on demand)
    parity.json           Python's answers to the page's inputs, for the tests (parity.py; not fetched)
    manifest.json         the vocabulary, signals, messages (web/messages.py), the form's choices
                          (episodes.play_choices), models, the episodes' index (with where each
                          episode's cubes lay), the normaliser's joint units, NICO's arm for forward
                          kinematics, and the file sizes

The page (``book/_js/pgae.js``) builds each signal's inputs from these as
:func:`pgae_lite.model.signals.make_batch` does, runs the graph with onnxruntime-web and
turns the joints back into data units. The free-text files (transformer, heads, tokenizer, word
tables) are fetched only when a reader types a sentence that is not a description.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import torch

from pgae_lite.bert.pretrained import fixed_token_rows, tokens_to_text
from pgae_lite.config import Profile
from pgae_lite.data.dataset import JOINT_DIM, VISION_DIM
from pgae_lite.model.signals import ACTION_IN, EOS, LANG_IN, LANG_OUT, SIGNAL_TOKEN
from pgae_lite.robot.instructions import default_route
from pgae_lite.runs.data import SimulatedData, loaded, profile_of
from pgae_lite.runs.pipeline import trained_model
from pgae_lite.runs.rows import TRAININGS
from pgae_lite.util.storage import atomic_write, atomic_write_text, make_folder
from pgae_lite.web.episodes import FILES, episode_index, page_rows, play_choices
from pgae_lite.web.export import to_onnx
from pgae_lite.web.free_text import export_free_text
from pgae_lite.web.messages import page_messages
from pgae_lite.web.parity import write_parity
from pgae_lite.web.sim_runs import chosen_episodes, simulator_runs
from pgae_lite.world.colours import CUBE_RGBA
from pgae_lite.world.typed import typed_rules
from pgae_lite.world.words import DEFAULT_LEXICON, SIGNALS, SLOT_NAMES, SLOTS, SYNONYMS, VOCABULARY

#: The models the playground offers, by the name the page shows, and their trainings.
MODELS = {name: TRAININGS[name] for name in ("PGAE", "PGAE-BERT", "PGAE-BERT-phrasings")}


def _arm() -> dict:
    """NICO's left arm as the simulator builds it (:func:`pgae_lite.sim.robot.nico_urdf`), for forward
    kinematics in the page, and the table the cubes stand on (metres, NICO's frame = the world's)."""
    from pgae_lite.sim.robot import FINGERTIP, FOREARM, SHOULDER, UPPER_ARM
    from pgae_lite.sim.scene import CUBE_SIZE, TABLE_HALF_WIDTH, TABLE_X

    return {"shoulder": list(SHOULDER), "upper_arm": UPPER_ARM, "forearm": FOREARM, "fingertip": FINGERTIP,
            "table_x": list(TABLE_X), "table_half_width": TABLE_HALF_WIDTH, "cube_size": CUBE_SIZE}


def _frames(out: Path, episodes: list[dict], config) -> str:
    """NICO's recorded camera frames at the first and last step of every episode of the page, as PNG files; the
    pattern of their names in ``out`` (``{episode}``: an id without ``sim/``; ``{which}``: first or last)."""
    from matplotlib.image import imsave

    from pgae_lite.sim.dataset import load_episode

    make_folder(out / "frames")
    for episode in episodes:
        name = episode["id"].removeprefix("sim/")                          # "PPP-V"
        pattern, variation = map(int, name.split("-"))
        images = load_episode(config, pattern, variation).images          # (T, 120, 160, 3) uint8
        for which, frame in (("first", images[0]), ("last", images[episode["steps"] - 1])):
            with atomic_write(out / "frames" / f"{name}-{which}.png") as f:
                imsave(f, frame, format="png")
    return "frames/{episode}-{which}.png"


def export_web(out: str | Path, profile: Profile, seed: int = 0, progress: bool = False,
               simulate: bool = True, half: bool = True, parity: bool = True) -> dict:
    """Write the playground's models and episodes to ``out`` (see the module docstring); the manifest.
    ``simulate=False``: without the simulator's runs (the page then keeps the cubes where they lay);
    ``half=False``: the sentence encoder's weights in float32 (:func:`~pgae_lite.web.free_text.export_free_text`);
    ``parity=False``: without the parity vectors (:mod:`~pgae_lite.web.parity`)."""
    prof = profile_of(profile)
    out = make_folder(out)
    make_folder(out / "models")
    source = SimulatedData(prof)
    data = loaded(source, "cpu", progress)
    trained = {name: trained_model(training, prof, seed, device="cpu", progress=progress)
               for name, training in MODELS.items()}
    models, encoders, normaliser = {}, {}, None
    # the fixed inputs the playground's signals read (not "repeat both", a training signal)
    rows = fixed_token_rows()
    rows = rows[rows[:, 0] != SIGNAL_TOKEN + SIGNALS.index("repeat both")]          # (581, 5)
    for name, run in trained.items():
        model = run.model.cpu().eval()
        if normaliser is not None and normaliser != run.normaliser:
            raise ValueError(f"{name} was trained with other data units than the first model: the page holds "
                             "one copy of the episodes, normalised once")
        normaliser = run.normaliser
        entry = {"file": f"models/{name}.onnx", "bytes": len(to_onnx(model, out / "models" / f"{name}.onnx")),
                 "reads": "features" if model.language_encoder.reads_free_text else "tokens",
                 "route": default_route(run.profile)}          # free text under execute, unless the reader says
        if entry["reads"] == "features":
            with torch.no_grad():
                table = model.language_encoder(rows).numpy().astype(np.float32)   # (rows, D)
            with atomic_write(out / "models" / f"{name}.table") as f:
                f.write(table.tobytes())
            entry |= {"table": f"models/{name}.table", "features": int(table.shape[1])}
            encoders[name] = model.language_encoder
        models[name] = entry
    free_text = export_free_text(out, encoders, models, half) if encoders else None
    episodes, files = [], {}
    for split, chosen in page_rows(data).items():                     # every test episode, one per training pattern
        values, index = episode_index(data, chosen, split, normaliser, prof.data)
        with atomic_write(out / FILES[split]) as f:
            f.write(values.tobytes())
        episodes += index
        files[split] = FILES[split]
    frames = _frames(out, episodes, prof.data)
    test = data.split("test")                                          # the simulator's runs: sim_runs.py
    manifest = {
        "profile": prof.name, "seed": seed, "vocabulary": list(VOCABULARY), "synonyms": SYNONYMS,
        "canonical": dict(DEFAULT_LEXICON.canonical), "slots": [list(slot) for slot in SLOTS],
        "slot_names": list(SLOT_NAMES), "signals": list(SIGNALS), "reads_words": [bool(x) for x in LANG_IN],
        "sees_action": [bool(x) for x in ACTION_IN], "lang_out": [bool(x) for x in LANG_OUT],
        "describe": SIGNALS.index("describe"), "repeat_language": SIGNALS.index("repeat language"),
        "signal_token": SIGNAL_TOKEN, "eos": EOS, "vision_dim": VISION_DIM, "joint_dim": JOINT_DIM,
        "messages": page_messages(), "play": play_choices(data, prof.data), "typed": typed_rules(),
        "models": models, "episodes": episodes, "episodes_files": files, "joint_units": list(normaliser.joints),
        "fixed_rows": {",".join(map(str, row)): r for r, row in enumerate(rows.tolist())},
        "fixed_texts": {tokens_to_text(row): r for r, row in enumerate(rows)}, "free_text": free_text,
        "arm": _arm(), "cube_rgba": {c: list(v) for c, v in CUBE_RGBA.items()},
        "sim_runs": "sim_runs.json" if simulate else None, "frames": frames,
        "sim_run_episodes": [str(test.ids[i]) for i in chosen_episodes(test)] if simulate else [],
    }
    if simulate:
        simulator_runs(out, trained, source, {"profile": prof.name, "seed": seed}, progress=progress)
    if parity:
        write_parity(out, trained, data, normaliser, episodes)
    atomic_write_text(out / "manifest.json", json.dumps(manifest))
    return manifest


__all__ = ["MODELS", "export_web"]
