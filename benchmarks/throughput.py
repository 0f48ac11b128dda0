"""Training throughput of PGAE on the authors' data: samples per second and seconds per epoch.

    python benchmarks/throughput.py [--original-data PATH] [--batches 6 64] [--cells lstm peephole]
                                    [--feedback own start] [--seconds 10] [--profile book] [--threads 2]

For each cell and batch size it times full training steps (signals drawn per
sample, forward, loss, backward, Adam) of the profile's model for each way
the action decoder reads joints: ``own`` (its own predictions, the paper's)
and ``start`` (the start joints at every step, joint_feedback="start"), and
extrapolates to one epoch of the 648 training samples. ``--seeds`` seed the
model and the batches (a row per seed). Writes results/throughput.json. Run it
on an otherwise idle machine.
"""
from __future__ import annotations

import time
from dataclasses import replace

import torch

from harness import Benchmark
from pgae_lite.config import get_profile
from pgae_lite.data.dataset import Normaliser
from pgae_lite.world.words import word_weights
from pgae_lite.data.original import load_original
from pgae_lite.model.pgae import PGAE
from pgae_lite.model.signals import make_batch, sample_signals
from pgae_lite.train.loss import pgae_loss


def seconds_per_step(model: PGAE, tensors: dict, samples: int, batch: int, seed: int, budget: float) -> float:
    """Mean wall time of one training step at ``batch``, over ``budget`` seconds after one warm-up step."""
    opt = torch.optim.Adam(model.parameters(), 1e-3)
    gen = torch.Generator().manual_seed(seed)
    weights = word_weights()

    def step():
        index = torch.randint(samples, (batch,), generator=gen)
        signals = sample_signals(batch, gen)
        data = make_batch(tensors, index, signals, torch.randint(8, (batch,), generator=gen))
        out = model(data, teacher_language=True)
        loss = pgae_loss(out, data, weights)[0]
        opt.zero_grad()
        loss.backward()
        opt.step()
    step()
    n, t0 = 0, time.perf_counter()
    while time.perf_counter() - t0 < budget:
        step()
        n += 1
    return (time.perf_counter() - t0) / n


def main() -> None:
    bench = Benchmark("throughput", __doc__)
    bench.add_original_data()
    bench.parser.add_argument("--batches", type=int, nargs="+", default=[6, 64])
    bench.parser.add_argument("--cells", nargs="+", default=["lstm", "peephole"])
    bench.parser.add_argument("--feedback", nargs="+", default=["own", "start"], choices=["own", "start"])
    bench.parser.add_argument("--seconds", type=float, default=10.0, help="time budget per measurement")
    args = bench.parse()

    data = load_original(args.original_data).split("train")
    tensors = Normaliser.fit(data).tensors(data)
    model_config = get_profile(args.profile).model
    rows = []
    for seed in args.seeds:
        for cell in args.cells:
            for batch in args.batches:
                for feedback in args.feedback:
                    torch.manual_seed(seed)
                    model = PGAE(replace(model_config, cell=cell,
                                         joint_feedback="start" if feedback == "start" else "predicted"))
                    dt = seconds_per_step(model, tensors, len(data), batch, seed, args.seconds)
                    row = {"seed": seed, "cell": cell, "batch": batch, "joints": feedback,
                           "samples_per_s": round(batch / dt, 1), "s_per_epoch": round(dt * len(data) / batch, 2)}
                    rows.append(row)
                    print(row, flush=True)
    bench.write({"data": "original", "training_samples": len(data), "time_stride": model_config.time_stride,
                 "seconds_budget": args.seconds, "rows": rows})


if __name__ == "__main__":
    main()
