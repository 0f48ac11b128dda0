"""Speed (and, with --profile, quality) of the channel-separated CAE on a CPU or GPU.

    python benchmarks/cae_speed.py [--threads 1 2] [--batches 16 32 200] [--seconds 8]
    python benchmarks/cae_speed.py --profile book [--data sim --episodes 48] [--threads 2]

Without --profile it times training steps (forward, BCE, backward, Adam) at each
batch size, and feature extraction (``extract_features``), in ms per image.
With --profile it trains that CAE profile end to end on tabletop frames and
reports the wall time, ms per iteration, the final training loss and, on
held-out frames, the BCE above its floor (the BCE of a perfect reconstruction,
which is not 0 for grey pixels) next to that of the mean training image.
Frames: ``synthetic`` (numpy: a table, an arm, two coloured cubes; no
simulator needed) or ``sim`` (episodes of ``pgae_lite.sim.record_episode``).
Each result is printed and appended as a json line to benchmarks/out/cae_speed.jsonl.
Run it on an otherwise idle machine.
"""
import argparse
import json
import os
import platform
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import torch

from pgae_lite.cae import (
    ChannelSeparatedCAE,
    extract_features,
    reconstruct,
    train_cae,
)
from pgae_lite.config import get_profile
from pgae_lite.utils import default_device

COLOURS = [(200, 35, 30), (40, 170, 50), (35, 60, 205), (225, 210, 40), (40, 200, 215), (150, 45, 190)]


def synthetic_episode(rng: np.random.Generator, steps: int = 40) -> np.ndarray:
    """(steps, 120, 160, 3) uint8: wall, grey table, two cubes; an arm reaches one cube and moves it."""
    yy, xx = np.mgrid[:120, :160]
    base = np.empty((120, 160, 3), np.uint8)
    base[:38] = (205, 200, 190)                                          # wall
    base[38:] = np.linspace(150, 115, 82)[:, None, None].astype(np.uint8)  # table, darker nearer
    group = rng.integers(2) * 3
    colours = [COLOURS[group + i] for i in rng.choice(3, 2, replace=False)]
    cubes = np.array([[68.0, 50.0], [68.0, 98.0]]) + rng.normal(0, 2, (2, 2))
    which, move = rng.integers(2), [(-14, 0), (14, 0), (0, 14), (0, -14)][rng.integers(4)]
    shoulder, rest = np.array([125.0, 25.0]), np.array([105.0, 45.0])
    frames = []
    for s in np.linspace(0, 1, steps):
        k = np.clip((s - 0.4) / 0.45, 0, 1)                             # reach until 0.4, then move the cube
        pos = cubes.copy()
        pos[which] += np.multiply(move, k)
        hand = rest + (cubes[which] + 5 - rest) * min(s / 0.4, 1) + np.multiply(move, k)
        img = base.copy()
        for (y, x), c in zip(pos.round().astype(int), colours):
            img[y:y + 11, x:x + 11] = np.multiply(c, 0.65)                # front face
            img[y:y + 8, x:x + 11] = np.minimum(np.multiply(c, 1.1), 255)  # top face
        elbow = (shoulder + hand) / 2 + (8, -12)
        for p, q, width in ((shoulder, elbow, 9), (elbow, hand, 7)):
            d = q - p                                                    # arm segment p -> q
            t = np.clip(((yy - p[0]) * d[0] + (xx - p[1]) * d[1]) / (d @ d), 0, 1)
            img[np.hypot(yy - p[0] - t * d[0], xx - p[1] - t * d[1]) <= width / 2] = (230, 230, 225)
        y, x = hand.round().astype(int)
        img[max(y - 4, 0):y + 4, max(x - 4, 0):x + 4] = (60, 60, 65)    # hand
        frames.append(img)
    return np.stack(frames)


def frames(kind: str, episodes: int, stride: int, seed: int) -> np.ndarray:
    """Every ``stride``-th frame of ``episodes`` episodes (both views for ``sim``), uint8 (N, 120, 160, 3)."""
    if kind == "synthetic":
        rng = np.random.default_rng(seed)
        return np.concatenate([synthetic_episode(rng)[::stride] for _ in range(episodes)])
    from pgae_lite.sim import record_episode
    eps = [record_episode(pattern=int(p), variation=seed % 6)
           for p in np.random.default_rng(seed).permutation(144)[:episodes]]
    return np.concatenate([view[::stride] for ep in eps for view in (ep.images, ep.images_opposite)])


def bce_floor(x: np.ndarray, p: np.ndarray | None = None) -> float:
    """Mean BCE of predicting ``p`` (default: x itself, the floor) for pixels x, both in [0, 1]."""
    p = np.clip(x if p is None else p, 1e-6, 1 - 1e-6)
    return float(-(x * np.log(p) + (1 - x) * np.log(1 - p)).mean())


def time_steps(model, opt, x, batch, seconds) -> float:
    def step():
        loss, _ = model.loss(x[:batch])
        opt.zero_grad(set_to_none=True)
        loss.backward()
        opt.step()
    step()
    n, t0 = 0, time.perf_counter()
    while time.perf_counter() - t0 < seconds or n < 2:
        step()
        n += 1
    if model.device.type == "cuda":
        torch.cuda.synchronize()
    return (time.perf_counter() - t0) / n


def time_extraction(model, x, seconds) -> float:
    extract_features(model, x[:128])
    n, t0 = 0, time.perf_counter()
    while time.perf_counter() - t0 < seconds or n < 1:
        extract_features(model, x)
        n += len(x)
    return (time.perf_counter() - t0) / n


ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
ap.add_argument("--threads", type=int, nargs="+", default=[1, 2])
ap.add_argument("--batches", type=int, nargs="+", default=[16, 32])
ap.add_argument("--seconds", type=float, default=8.0, help="time budget per measurement")
ap.add_argument("--profile", help="train this CAE profile end to end (smoke / book / paper)")
ap.add_argument("--iterations", type=int, help="override the profile's iterations")
ap.add_argument("--data", choices=["synthetic", "sim"], default="synthetic")
ap.add_argument("--episodes", type=int, default=48, help="episodes of frames for --profile")
ap.add_argument("--stride", type=int, default=4, help="every k-th frame of those episodes")
ap.add_argument("--png", help="with --profile: save test frames above their reconstructions here")
args = ap.parse_args()

x_device = default_device()
out = Path(__file__).parent / "out" / "cae_speed.jsonl"
out.parent.mkdir(parents=True, exist_ok=True)
base = {"device": str(x_device), "cpu": platform.processor() or platform.machine(), "torch": torch.__version__,
        "load_avg_1min": os.getloadavg()[0]}  # > 0.5 before we start: another job shares the cores
if x_device.type == "cuda":
    base["gpu"] = torch.cuda.get_device_name()
rows = []
for threads in args.threads:
    torch.set_num_threads(threads)
    if args.profile:
        config = replace(get_profile(args.profile).cae, **({"iterations": args.iterations} if args.iterations else {}))
        data = frames(args.data, args.episodes, args.stride, seed=0)
        test = frames(args.data, max(2, args.episodes // 8), 4, seed=1)
        t0 = time.perf_counter()
        model, history = train_cae(data, config, device=x_device, progress=False)
        seconds = time.perf_counter() - t0
        with torch.no_grad():
            test_bce = sum(model.loss(test[i:i + 128])[0].item() * len(test[i:i + 128])
                           for i in range(0, len(test), 128)) / len(test)
        x, mean = test / 255.0, data.mean(0) / 255.0
        floor = bce_floor(x)
        rec = reconstruct(model, test)
        row = {**base, "profile": config.name, "data": args.data, "threads": threads, "images": len(data),
               "batch": config.batch_size, "iterations": config.iterations, "train_s": round(seconds, 1),
               "ms_per_iteration": round(seconds / config.iterations * 1000, 1),
               "final_loss": round(float(np.mean([h["loss"] for h in history[-50:]])), 4),
               "test_bce_above_floor": round(test_bce - floor, 4),
               "mean_image_bce_above_floor": round(bce_floor(x, mean) - floor, 4),
               "test_mae_0_255": round(float(np.abs(rec.astype(float) - test).mean()), 2),
               "extract_ms_per_image": round(time_extraction(model, test[:256], 2.0) * 1000, 3)}
        if args.png:
            import matplotlib
            matplotlib.use("Agg")
            import matplotlib.pyplot as plt
            pick = np.linspace(0, len(test) - 1, 6).astype(int)
            fig, axes = plt.subplots(2, 6, figsize=(15, 4))
            for j, i in enumerate(pick):
                axes[0, j].imshow(test[i])
                axes[1, j].imshow(rec[i])
            for a in axes.flat:
                a.axis("off")
            fig.tight_layout()
            fig.savefig(args.png, dpi=70)
    else:
        x = frames("synthetic", 13, 1, seed=0)[:512]                     # 512 frames
        torch.manual_seed(0)
        model = ChannelSeparatedCAE().to(x_device)
        opt = torch.optim.Adam(model.parameters(), 1e-3)
        row = {**base, "threads": threads}
        for batch in args.batches:
            dt = time_steps(model.train(), opt, x, batch, args.seconds)
            row[f"train_b{batch}_ms_per_iteration"] = round(dt * 1000, 1)
            row[f"train_b{batch}_ms_per_image"] = round(dt / batch * 1000, 2)
        row["extract_ms_per_image"] = round(time_extraction(model, x[:256], args.seconds) * 1000, 3)
    rows.append(row)
    print(json.dumps(row), flush=True)
    with out.open("a") as f:
        f.write(json.dumps(row) + "\n")
