"""Training throughput of PGAE on the authors' data: samples per second and seconds per epoch.

    python benchmarks/throughput.py [--data PATH] [--batches 6 64] [--cells lstm peephole]
                                    [--feedback own start]

For each cell and batch size it times full training steps (signals drawn per
sample, forward, loss, backward, Adam) for each way the action decoder reads
joints: ``own`` (its own predictions, the paper's) and ``start`` (the start joints at every step, joint_feedback="start"),
and extrapolates to one epoch of the 648 training samples. Run it on an
otherwise idle machine.
"""
import argparse
import json
import time

import torch

from pgae_lite.config import ModelConfig
from pgae_lite.data import Normaliser
from pgae_lite.language import word_weights
from pgae_lite.original import load_original
from pgae_lite.pgae import PGAE
from pgae_lite.signals import make_batch, sample_signals
from pgae_lite.train import pgae_loss

ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
ap.add_argument("--data", default="../shared/pgae-original-data")
ap.add_argument("--batches", type=int, nargs="+", default=[6, 64])
ap.add_argument("--cells", nargs="+", default=["lstm", "peephole"])
ap.add_argument("--feedback", nargs="+", default=["own", "start"], choices=["own", "start"])
ap.add_argument("--threads", type=int, default=None, help="torch threads (default: torch's choice)")
ap.add_argument("--seconds", type=float, default=10.0, help="time budget per measurement")
args = ap.parse_args()
if args.threads:
    torch.set_num_threads(args.threads)

data = load_original(args.data).split("train")
tensors = Normaliser.fit(data).tensors(data)
weights = word_weights()
rows = []
for cell in args.cells:
    for bs in args.batches:
        for feedback in args.feedback:
            torch.manual_seed(0)
            model = PGAE(ModelConfig(cell=cell, joint_feedback="start" if feedback == "start" else "predicted"))
            opt = torch.optim.Adam(model.parameters(), 1e-3)
            gen = torch.Generator().manual_seed(0)

            def step():
                index = torch.randint(len(data), (bs,), generator=gen)
                batch = make_batch(tensors, index, sample_signals(bs, gen), torch.randint(8, (bs,), generator=gen))
                out = model(batch, teacher_language=True)
                loss = pgae_loss(out, batch, weights)[0]
                opt.zero_grad()
                loss.backward()
                opt.step()
            step()
            n, t0 = 0, time.perf_counter()
            while time.perf_counter() - t0 < args.seconds:
                step()
                n += 1
            dt = (time.perf_counter() - t0) / n
            row = {"cell": cell, "batch": bs, "joints": feedback,
                   "samples_per_s": round(bs / dt, 1), "s_per_epoch": round(dt * len(data) / bs, 2)}
            rows.append(row)
            print(json.dumps(row), flush=True)
