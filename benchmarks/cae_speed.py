"""Speed (and, with --train, quality) of the channel-separated CAE on a CPU or GPU.

    python benchmarks/cae_speed.py [--batches 16 32 200] [--seconds 8] [--threads 1]
    python benchmarks/cae_speed.py --train [--profile book] [--frames sim --episodes 48] [--threads 2]

Without --train it times training steps (forward, BCE, backward, Adam) of a
CAE of the default architecture at each batch size, and feature extraction
(``extract_features``), in ms per image; writes results/cae_speed.json.
With --train it trains the profile's CAE end to end on tabletop frames and
reports the wall time, ms per iteration, the final training loss and, on
held-out frames, the BCE above its floor (the BCE of a perfect reconstruction,
which is not 0 for grey pixels) next to that of the mean training image;
writes results/cae_speed-train.json. Frames: ``synthetic`` (numpy: a table,
an arm, two coloured cubes; no simulator needed) or ``sim`` (episodes of
``pgae_lite.sim.record_episode``); the same frames for every seed, which
seeds the CAE's weights (a row per seed). One thread count per run
(``--threads``; compare counts with one run each and ``--out``). Run it on an
otherwise idle machine.
"""
from __future__ import annotations

import os
import time
from dataclasses import replace

import numpy as np
import torch
from harness import Benchmark

from pgae_lite.cae import (
    ChannelSeparatedCAE,
    extract_features,
    reconstruct,
    train_cae,
)
from pgae_lite.config import Profile, get_profile
from pgae_lite.util.storage import default_device

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


def trained_row(args, profile: Profile, seed: int, device: torch.device) -> dict:
    """Train the profile's CAE (seeded ``seed``) on ``--frames`` frames; its time and reconstruction quality."""
    config = replace(profile.cae, seed=seed,
                     **({"iterations": args.iterations} if args.iterations else {}))
    data = frames(args.frames, args.episodes, args.stride, seed=0)
    test = frames(args.frames, max(2, args.episodes // 8), 4, seed=1)
    t0 = time.perf_counter()
    model, history = train_cae(data, config, device=device, progress=False)
    seconds = time.perf_counter() - t0
    with torch.no_grad():
        test_bce = sum(model.loss(test[i:i + 128])[0].item() * len(test[i:i + 128])
                       for i in range(0, len(test), 128)) / len(test)
    x, mean = test / 255.0, data.mean(0) / 255.0
    floor = bce_floor(x)
    rec = reconstruct(model, test)
    return {"seed": seed, "cae": config.name, "images": len(data), "batch": config.batch_size,
            "iterations": config.iterations, "train_s": round(seconds, 1),
            "ms_per_iteration": round(seconds / config.iterations * 1000, 1),
            "final_loss": round(float(np.mean([h["loss"] for h in history[-50:]])), 4),
            "test_bce_above_floor": round(test_bce - floor, 4),
            "mean_image_bce_above_floor": round(bce_floor(x, mean) - floor, 4),
            "test_mae_0_255": round(float(np.abs(rec.astype(float) - test).mean()), 2),
            "extract_ms_per_image": round(time_extraction(model, test[:256], 2.0) * 1000, 3)}


def speed_row(args, seed: int, device: torch.device) -> dict:
    """Training steps at each batch size and feature extraction of a fresh CAE (seeded ``seed``), ms per image."""
    x = frames("synthetic", 13, 1, seed=0)[:512]                         # 512 frames
    torch.manual_seed(seed)
    model = ChannelSeparatedCAE().to(device)
    opt = torch.optim.Adam(model.parameters(), 1e-3)
    row = {"seed": seed}
    for batch in args.batches:
        dt = time_steps(model.train(), opt, x, batch, args.seconds)
        row[f"train_b{batch}_ms_per_iteration"] = round(dt * 1000, 1)
        row[f"train_b{batch}_ms_per_image"] = round(dt / batch * 1000, 2)
    row["extract_ms_per_image"] = round(time_extraction(model, x[:256], args.seconds) * 1000, 3)
    return row


def main() -> None:
    bench = Benchmark("cae_speed", __doc__)
    bench.parser.add_argument("--batches", type=int, nargs="+", default=[16, 32], help="batch sizes (without --train)")
    bench.parser.add_argument("--seconds", type=float, default=8.0, help="time budget per measurement")
    bench.parser.add_argument("--train", action="store_true", help="train the profile's CAE end to end")
    bench.parser.add_argument("--iterations", type=int, help="with --train: override the profile's iterations")
    bench.parser.add_argument("--frames", choices=["synthetic", "sim"], default="synthetic",
                              help="with --train: the frames")
    bench.parser.add_argument("--episodes", type=int, default=48, help="with --train: episodes of frames")
    bench.parser.add_argument("--stride", type=int, default=4, help="with --train: every k-th frame of those episodes")
    args = bench.parse()
    if args.train:
        bench.name = "cae_speed-train"         # results/cae_speed-train.json
    device = default_device()
    load = os.getloadavg()[0]                  # > 0.5 before we start: another job shares the cores
    profile = get_profile(args.profile)        # resolved once, here
    rows = []
    for seed in args.seeds:
        rows.append(trained_row(args, profile, seed, device) if args.train else speed_row(args, seed, device))
        print(rows[-1], flush=True)
    bench.write({"mode": "train" if args.train else "steps", "device": str(device), "load_average": load,
                 **({"data": args.frames, "episodes": args.episodes, "stride": args.stride} if args.train
                    else {"batches": args.batches}), "rows": rows})


if __name__ == "__main__":
    main()
