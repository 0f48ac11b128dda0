"""The figures of the exercises whose solutions train something (not in the paper): each solution's own run.

    python benchmarks/exercise_runs.py [--exercises ex-cae-rgb ex-bert-cls ...] [--threads 1]
                                       [--seeds 0 1 2] [--original-data PATH]

Each function below runs what the solution of one exercise runs, the same change through the same
calls of the package (``train_cae``, ``trained_cae``, ``train``, ``trained_model``, ``evaluate``), in
the profile given (``book``: the one the chapters' figures are read against), and returns its figures.
An exercise's trainings run on the seeds of :data:`EXERCISES` (0 alone where one training takes
over 3 minutes on one core, else 0, 1 and 2), or on ``--seeds``. The figures merge into
results/exercise_runs.json, one entry per exercise label, each with its own command, commit, date
and seconds, so that exercises can be run one at a time; the solutions quote them from there. The
exercises of chapters 06 and 07 and appendices A3 and A4 are in benchmarks/exercise_runs_acting.py
(its ``EXERCISES`` merge into this one's). The exercises whose runs this benchmark cannot make are
named, with the reason, in tests/test_exercise_solutions.py (``AWAITING_A_RESULT``).
"""
from __future__ import annotations

import copy
import datetime
import json
import subprocess
import sys
import tempfile
import time
from collections import Counter
from dataclasses import replace
from pathlib import Path

import numpy as np
import torch
from exercise_runs_acting import EXERCISES as ACTING
from exercise_runs_acting import cells
from harness import ROOT, Benchmark
from torch import nn
from torch.nn import functional as F

import pgae_lite.model.pvae as pvae_module
from pgae_lite.bert.pretrained import PretrainedLanguageEncoder
from pgae_lite.cae import ChannelAutoencoder, ChannelSeparatedCAE, as_input, extract_features, train_cae
from pgae_lite.config import get_profile
from pgae_lite.model.build import build_model
from pgae_lite.model.layers import ConcatBottleneck
from pgae_lite.model.pgae import PGAE
from pgae_lite.model.signals import make_batch, signal_ids
from pgae_lite.runs import results
from pgae_lite.runs.data import cae_path, trained_cae, worker_dataset
from pgae_lite.runs.pipeline import trained_model, unit_profile
from pgae_lite.runs.rows import TRAININGS, Training
from pgae_lite.sim import record_episode
from pgae_lite.sim.dataset import load_episode, training_frames
from pgae_lite.train.loop import train
from pgae_lite.train.supervision import SupervisionConfig
from pgae_lite.util.storage import load_torch

NO_BOTH = (3 / 8, 3 / 8, 1 / 8, 0.0, 1 / 8)        # ex-a1-no-both: describe, execute, repeat action, -, language
SCENES = range(0, 36, 6)                          # chapter 03, section 6: push left slowly, arrangements 0-5
SWAPS = [("red + blue", "blue + red"), ("green + red", "red + green"), ("blue + green", "green + blue")]


def final_bce(losses: list[float]) -> float:
    return round(float(np.mean(losses[-50:])), 5)             # chapter 03: the mean of the last 50 iterations


def levels(frames: np.ndarray) -> dict:
    """Chapter 03's two reference levels (BCE, mean of the 3 channels): the floor and the mean image."""
    x = frames.astype(np.float32) / 255.0                     # (N, 120, 160, 3)

    def bce(x_hat):
        x_hat = np.clip(x_hat, 1e-6, 1 - 1e-6)
        return float(-(x * np.log(x_hat) + (1 - x) * np.log(1 - x_hat)).mean())
    return {"floor": round(bce(x), 5), "mean_image": round(bce(x.mean(axis=0)), 5)}


def fit(model, images, config, loss_of=lambda m, batch: m.loss(batch)[0]):
    """Chapter 03's short training loop of ex-cae-batchnorm (the CAE's recipe)."""
    torch.manual_seed(config.seed)
    optimiser = torch.optim.Adam(model.parameters(), lr=config.lr)
    batches = np.random.default_rng(config.seed)
    losses = []
    for _ in range(config.iterations):
        loss = loss_of(model, images[np.sort(batches.choice(len(images), config.batch_size, replace=False))])
        optimiser.zero_grad()
        loss.backward()
        optimiser.step()
        losses.append(loss.item())
    return model.eval(), losses


def the_cae(profile):
    """The profile's CAE (cached), its history and its training seconds."""
    model, history = trained_cae(profile, progress=False)
    seconds = load_torch(cae_path(profile.data, profile.cae), ("seconds",))["seconds"]
    return model, history, round(seconds, 1)


# --------------------------------------------------------------------------- chapter 03
def cae_bottleneck(profile, seeds, **_):
    frames = training_frames(profile.data, profile.cae.frame_stride)
    _, history, seconds = the_cae(profile)
    runs = [{"features": profile.cae.features, "seed": profile.cae.seed, "train_seconds": seconds,
             "final_bce": final_bce([r["loss"] for r in history])}]
    for seed in seeds:
        for f in (5, 20):
            t0 = time.perf_counter()
            _, h = train_cae(frames, replace(profile.cae, features=f, seed=seed, name=f"{profile.name}-{f}"),
                             progress=False)
            runs.append({"features": f, "seed": seed, "train_seconds": round(time.perf_counter() - t0, 1),
                         "final_bce": final_bce([r["loss"] for r in h])})
    return {"levels": levels(frames[::20]), "runs": runs}


def without_batchnorm(model):
    for ae in model.channels:
        for seq in (ae.conv, ae.deconv):
            for i, layer in enumerate(seq):
                if isinstance(layer, nn.BatchNorm2d):
                    seq[i] = nn.Identity()
                    conv = seq[i - 1]
                    conv.bias = nn.Parameter(torch.zeros(conv.out_channels))
    return model


def curve(losses: list[float], every: int = 50) -> list[float]:
    return [round(float(np.mean(losses[i:i + every])), 5) for i in range(0, len(losses), every)]


def cae_batchnorm(profile, seeds, **_):
    frames = training_frames(profile.data, profile.cae.frame_stride)
    model, history, _ = the_cae(profile)
    shown = frames[::50]                                         # features' spread over these frames
    with torch.no_grad():
        spread = float(model.encode(shown).std(dim=0).mean())
    runs = []
    for seed in seeds:
        config = replace(profile.cae, seed=seed)
        t0 = time.perf_counter()
        torch.manual_seed(config.seed)
        plain, losses = fit(without_batchnorm(ChannelSeparatedCAE(config)), frames, config)
        with torch.no_grad():
            plain_spread = float(plain.encode(shown).std(dim=0).mean())
        runs.append({"seed": seed, "train_seconds": round(time.perf_counter() - t0, 1),
                     "final_bce": final_bce(losses), "curve": curve(losses), "feature_std": round(plain_spread, 5)})
    package = [r["loss"] for r in history]
    return {"levels": levels(frames[::20]), "package": {"final_bce": final_bce(package), "curve": curve(package),
                                                        "feature_std": round(spread, 5)}, "runs": runs}


def cae_rgb(profile, seeds, **_):
    cae = profile.cae
    frames = training_frames(profile.data, cae.frame_stride)
    model, history, seconds = the_cae(profile)

    def first_frame(pattern, variation=0):                     # chapter 03: recorded now if the profile lacks it
        if (pattern, variation) in profile.data.episodes():
            return load_episode(profile.data, pattern, variation).images[0]
        return record_episode(pattern, variation, profile.data.sim, profile.data.base_seed).images[0]
    scenes = {label: first_frame(p) for label, p in zip(
        ["red + blue", "green + red", "blue + green", "blue + red", "red + green", "green + blue"], SCENES)}
    again = np.stack([first_frame(0, v) for v in (0, 1)])     # one scene, two recordings
    shown = np.stack(list(scenes.values()))

    def distances(encode):
        f, yard = dict(zip(scenes, encode(shown))), encode(again)
        return {"swaps": {f"{a} vs {b}": round(float(np.linalg.norm(f[a] - f[b])), 4) for a, b in SWAPS},
                "two_recordings": round(float(np.linalg.norm(yard[0] - yard[1])), 4)}

    def rgb_loss(m, batch):
        x = as_input(batch)                                       # (B, 3, 120, 160) in [0, 1]
        return F.binary_cross_entropy_with_logits(m.logits(m.encode(x)), x)

    runs = []
    for seed in seeds:
        config = replace(cae, features=30, seed=seed)
        torch.manual_seed(seed)
        rgb = ChannelAutoencoder(config)
        rgb.conv[0] = nn.Conv2d(3, cae.conv[0], 4, 2, 1, bias=False)          # 3 channels in
        rgb.deconv[-1] = nn.ConvTranspose2d(cae.conv[0], 3, 4, 2, 1)          # 3 channels out
        t0 = time.perf_counter()
        rgb, losses = fit(rgb, frames, config, rgb_loss)
        seconds_rgb = round(time.perf_counter() - t0, 1)
        with torch.no_grad():
            runs.append({"seed": seed, "train_seconds": seconds_rgb, "final_bce": final_bce(losses),
                         "parameters": sum(p.numel() for p in rgb.parameters()),
                         **distances(lambda x: rgb.encode(as_input(x)).numpy())})
    separated = {"train_seconds": seconds, "final_bce": final_bce([r["loss"] for r in history]),
                 "parameters": sum(p.numel() for p in model.parameters()),
                 **distances(lambda x: extract_features(model, x))}
    return {"separated": separated, "runs": runs}


# --------------------------------------------------------------------------- chapter 05
def bert_baseline(profile, data, seed: int = 0) -> dict:
    """The chapter's PGAE-BERT (cached): its training time and Table 1."""
    bert = trained_model(TRAININGS["PGAE-BERT"], get_profile(profile), seed, progress=False)
    return {"train_seconds": round(bert.seconds, 1), "table1": cells(bert, data)}


def bert_with(part: str, new):
    """An exercise that trains PGAE-BERT with its ``part`` replaced by ``new(model)`` (chapter 05), against the
    chapter's PGAE-BERT."""
    def exercise(profile, seeds, **_):
        data, runs = worker_dataset(None, profile, "cpu"), []
        for seed in seeds:
            recipe = TRAININGS["PGAE-BERT"].profile(get_profile(profile, seed=seed))
            torch.manual_seed(seed)
            model = build_model(recipe.model)
            setattr(model, part, new(model))
            trained = train(data, recipe, model=model, progress=False)
            runs.append({"seed": seed, "train_seconds": round(trained.seconds, 1), "table1": cells(trained, data),
                         "baseline": bert_baseline(profile, data, seed)})
        return {"runs": runs}
    return exercise


def bert_readout(profile, seeds, **_):
    """``python experiments/paraphrase_readout.py`` (its own seed 0; no simulator, no profile)."""
    with tempfile.TemporaryDirectory() as folder:
        out = Path(folder) / "readout.json"
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "experiments/paraphrase_readout.py", "--out", str(out)], cwd=ROOT, check=True)
        found = json.loads(out.read_text())
    misses = Counter((m["slot"], m["meant"], m["read"]) for m in found["misses_of_last_row"]).most_common(6)
    return {"model": found["model"], "carriers": found["carriers"], "rows": found["results"],
            "common_misses": [{"slot": s, "meant": a, "read": b, "count": n} for (s, a, b), n in misses],
            "runs": [{"seed": 0, "train_seconds": round(time.perf_counter() - t0, 1)}]}


# --------------------------------------------------------------------------- chapter 09
def family_share(profile, seeds, **_):
    limited = results.value("limited_supervision", "table")
    share = min(r["share"] for r in limited if r["model"] == "PGAE" and r["reading"] == "updates"
                and r["stats"]["describe"]["accuracy"]["median"] >= 90.0)
    data, runs = worker_dataset(None, profile, "cpu"), []
    for seed in seeds:
        half = trained_model(Training("PGAE-half", train={"supervision": SupervisionConfig(share / 2)}),
                             get_profile(profile), seed, progress=False)
        runs.append({"seed": seed, "train_seconds": round(half.seconds, 1), "table1": cells(half, data)})
    return {"share": share / 2, "runs": runs}


def family_noise(profile, seeds, **_):
    data, runs = worker_dataset(None, profile, "cpu"), []
    test_set = data.split("test")

    def spread(trained):                                   # chapter 09, section 4
        t, every = trained.normaliser.tensors(test_set), np.arange(len(test_set))
        index = torch.as_tensor(every).repeat_interleave(8)
        b = make_batch(t, index, signal_ids("repeat both", len(index)), torch.arange(8).repeat(len(every)))
        with torch.no_grad():
            words = trained.model.language_code(b.lang_tokens, b.lang_lengths).reshape(len(every), 8, -1).numpy()
            action = trained.model.action_code(b.action_input[::8], b.action_lengths[::8]).numpy()
        own = np.linalg.norm(words - action[:, None], axis=-1).mean()
        apart = np.linalg.norm(action[:, None] - action[None], axis=-1)
        return float(own / apart[~np.eye(len(every), dtype=bool)].mean())

    saved = pvae_module.SAMPLING_STD
    for seed in seeds:
        pvae_module.SAMPLING_STD = 1.0                     # PVAE.sample reads it at every step
        try:
            noisy = train(data, unit_profile(get_profile(profile), TRAININGS["PVAE"], seed, data), name="PVAE",
                          progress=False)
        finally:
            pvae_module.SAMPLING_STD = saved
        runs.append({"seed": seed, "sampling_std": 1.0, "train_seconds": round(noisy.seconds, 1),
                     "table1": cells(noisy, data), "spread": round(spread(noisy), 4)})
    return {"runs": runs}


# --------------------------------------------------------------------------- appendix A1
def a1_change(kind: str):
    """ex-a1-no-both / ex-a1-concat: chapter 04's change, trained on the authors' data."""
    def exercise(profile, seeds, original_data=None, **_):
        if not original_data or not Path(original_data, "vocabulary.txt").is_file():
            raise SystemExit(f"{kind} trains on the authors' data: give --original-data PATH (got {original_data})")
        data, runs = worker_dataset(original_data, profile, "cpu"), []
        for seed in seeds:
            if kind == "no-both":
                trained = train(data, get_profile(profile, seed=seed, signal_probs=NO_BOTH), progress=False)
            else:
                recipe = get_profile(profile, seed=seed)
                torch.manual_seed(seed)
                concat = PGAE(recipe.model)
                concat.gmu = ConcatBottleneck(concat.cfg.state_dim, concat.cfg.state_dim, concat.cfg.hidden)
                trained = train(data, recipe, model=concat, progress=False)
            runs.append({"seed": seed, "train_seconds": round(trained.seconds, 1), "table1": cells(trained, data)})
        return {"data": "original", "runs": runs}
    return exercise


#: label -> (the exercise's run, its seeds by default)
EXERCISES = {
    "ex-cae-bottleneck": (cae_bottleneck, (0,)), "ex-cae-batchnorm": (cae_batchnorm, (0,)),
    "ex-cae-rgb": (cae_rgb, (0, 1, 2)),
    # [CLS] pooling: the same output size, the GMU fits
    "ex-bert-cls": (bert_with("language_encoder", lambda m: PretrainedLanguageEncoder(pooling="cls")), (0,)),
    "ex-bert-concat": (bert_with("gmu", lambda m: ConcatBottleneck(m.cfg.state_dim, m.language_encoder.output_dim,
                                                                   m.cfg.hidden)), (0,)),
    "ex-bert-readout": (bert_readout, (0,)),
    "ex-family-share": (family_share, (0,)), "ex-family-noise": (family_noise, (0,)),
    "ex-a1-no-both": (a1_change("no-both"), (0,)), "ex-a1-concat": (a1_change("concat"), (0,)),
    **ACTING,                                     # chapters 06 and 07, appendices A3 and A4
}


def main() -> None:
    bench = Benchmark("exercise_runs", __doc__)
    bench.parser.add_argument("--exercises", nargs="+", default=list(EXERCISES), choices=list(EXERCISES),
                              help="the exercises to run (default: all); the others' entries are kept")
    bench.parser.set_defaults(seeds=None)
    bench.add_original_data()
    args = bench.parse()
    profile = get_profile(args.profile)                       # resolved once, here
    found = json.loads(bench.path.read_text())["data"] if bench.path.is_file() else {}    # the entries kept
    chosen = args.seeds
    for label in args.exercises:
        run, seeds = EXERCISES[label]
        seeds = list(chosen or seeds)
        t0 = time.perf_counter()
        entry = run(copy.deepcopy(profile), seeds, original_data=args.original_data)
        found[label] = {"command": " ".join(["python benchmarks/exercise_runs.py", *sys.argv[1:]]),
                        "commit": bench.commit, "profile": profile.name, "seeds": seeds,
                        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
                        "seconds": round(time.perf_counter() - t0, 1), **entry}
        print(label, json.dumps(found[label])[:600], flush=True)
        bench.args.seeds = sorted({s for e in found.values() for s in e["seeds"]})
        bench.write(dict(sorted(found.items())))              # after each exercise: a crash keeps the others


if __name__ == "__main__":   # recording data spawns workers, which re-import this file
    main()
