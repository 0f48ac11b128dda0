"""Where one epoch of PGAE training spends its time, and how close it runs to the machine's peak.

    python benchmarks/profile_epoch.py [--original-data PATH] [--batches 6 16] [--epochs 2] [--threads 2]

On the authors' data (648 training samples; our simulated data has the same
shapes), with the book recipe's model and training options, for each batch
size: one warm-up epoch, then ``--epochs`` timed epochs of the real training
loop (:func:`pgae_lite.train.loop.train`), once in float32 and once under CPU
autocast to bfloat16 (``torch.autocast``: the LSTMs' and linear layers' matmuls
in bfloat16; the training options have no switch for it, since it did not pay
at the recipe's batch). Reports

- seconds per epoch and training samples per second;
- the arithmetic of one epoch: the multiply-adds of every LSTM and linear
  layer, counted from the batches the epoch drew (2 FLOP per multiply-add,
  backward = 2 x forward), and the achieved GFLOP/s;
- the machine's peak, measured here: a large float32 and a large bfloat16
  matmul on the same threads;
- where the time goes, from torch's profiler over one more epoch: the fused
  LSTM kernels (forward, backward), the optimiser, and everything else.

Writes results/profile_epoch.json.
"""
from __future__ import annotations

import contextlib
import math
import time

import torch
from harness import Benchmark
from torch.profiler import ProfilerActivity, profile

from pgae_lite.config import get_profile
from pgae_lite.data.dataset import JOINT_DIM, VISION_DIM
from pgae_lite.data.original import load_original
from pgae_lite.model.signals import ACTION_IN, LANG_IN, SIGNAL_PROBS
from pgae_lite.train.loop import train
from pgae_lite.world.words import INPUT_DIM, VOCABULARY

bench = Benchmark("profile_epoch", __doc__)
bench.add_original_data()
bench.parser.add_argument("--batches", type=int, nargs="+", default=None,
                          help="batch sizes (default: the paper's 6 and the recipe's)")
bench.parser.add_argument("--epochs", type=int, default=2, help="timed epochs per setting")
args = bench.parse()
recipe = get_profile(args.profile)                   # resolved once, here
batches = args.batches or sorted({6, recipe.train.batch_size})
dataset = load_original(args.original_data)
train_set = dataset.split("train")


def lstm_flops(inputs: int, units: int, layers: int, steps: float) -> float:
    """Forward FLOP of one sample through a stacked LSTM: 2 · 4H · (I + H) per layer and step."""
    return 2 * 4 * units * sum((inputs if layer == 0 else units) + units for layer in range(layers)) * steps


def epoch_flops(model_units: int = 100, layers: int = 2, hidden: int = 50, stride: int = 1) -> float:
    """Expected forward + backward FLOP of one epoch: every sample once, signals drawn as the recipe draws them.

    ``stride``: the model's time stride (the action LSTMs take one step per ``stride`` time steps).
    """
    lengths = torch.as_tensor(train_set.lengths, dtype=torch.float64)
    mean_len = float(lengths.mean())
    p = torch.tensor(SIGNAL_PROBS, dtype=torch.float64)
    action_steps = float((p * torch.tensor([mean_len if a else 1.0 for a in ACTION_IN])).sum())
    lang_steps = float((p * torch.tensor([5.0 if w else 2.0 for w in LANG_IN])).sum())
    state = 2 * layers * model_units
    per_sample = (lstm_flops(VISION_DIM + JOINT_DIM, model_units, layers, action_steps / stride)   # action encoder
                  + lstm_flops(INPUT_DIM, model_units, layers, lang_steps)                  # language encoder
                  + lstm_flops(len(VOCABULARY), model_units, layers, 4)                     # language decoder
                  + lstm_flops(VISION_DIM + JOINT_DIM, model_units, layers, (mean_len - 1) / stride)  # action decoder
                  + 2 * (2 * state * hidden + (2 * state) * hidden)                         # GMU
                  + 2 * 2 * hidden * state                                                  # decoder inits
                  + 2 * model_units * (len(VOCABULARY) * 4 + JOINT_DIM * (mean_len - 1)))  # read-outs
    return 3 * per_sample * len(train_set)


def peak(dtype: torch.dtype, n: int = 2048, reps: int = 10) -> float:
    """GFLOP/s of a large square matmul in ``dtype``."""
    a, b = torch.randn(n, n).to(dtype), torch.randn(n, n).to(dtype)
    a @ b
    t = time.perf_counter()
    for _ in range(reps):
        a @ b
    return 2 * n ** 3 * reps / (time.perf_counter() - t) / 1e9


def precision(bf16: bool):
    """bfloat16 autocast on the CPU, or nothing (float32)."""
    return torch.autocast("cpu", dtype=torch.bfloat16) if bf16 else contextlib.nullcontext()


def where_time_goes(batch: int, bf16: bool) -> dict:
    prof = get_profile(recipe, epochs=1, batch_size=batch)
    with profile(activities=[ProfilerActivity.CPU]) as p, precision(bf16):
        train(train_set, prof, progress=False)
    ops = p.key_averages()
    total = sum(k.self_cpu_time_total for k in ops)
    share = {"LSTM forward (fused kernel)": "mkldnn_rnn_layer", "LSTM backward (fused kernel)": "rnn_layer_backward",
             "optimiser (AdamW)": "adamw"}
    parts = {name: sum(k.self_cpu_time_total for k in ops if key in k.key.lower()
                       and not (key == "mkldnn_rnn_layer" and "backward" in k.key))
             for name, key in share.items()}
    parts["everything else (batches, linear layers, loss, autograd, Python)"] = total - sum(parts.values())
    calls = sum(k.count for k in ops if k.key.startswith("aten::"))
    return {"share_%": {k: round(100 * v / total, 1) for k, v in parts.items()},
            "aten_calls_per_batch": round(calls / math.ceil(len(train_set) / batch))}


model_cfg = recipe.model
flops = epoch_flops(model_cfg.units, model_cfg.layers, model_cfg.hidden, model_cfg.time_stride)
peaks = {"float32": peak(torch.float32), "bfloat16": peak(torch.bfloat16)}
print(f"one epoch: {flops / 1e9:.1f} GFLOP; matmul peak here: float32 {peaks['float32']:.0f}, "
      f"bfloat16 {peaks['bfloat16']:.0f} GFLOP/s")
rows = []
for batch in batches:
    for bf16 in (False, True):
        prof = get_profile(recipe, epochs=1 + args.epochs, batch_size=batch)
        times = []
        with precision(bf16):
            train(train_set, prof, progress=False,
                  callback=lambda epoch, model, rec: times.append(time.perf_counter()))
        seconds = (times[-1] - times[0]) / args.epochs
        row = {"batch": batch, "bf16": bf16, "seconds_per_epoch": round(seconds, 3),
               "samples_per_second": round(len(train_set) / seconds, 1),
               "gflops": round(flops / seconds / 1e9, 1),
               "share_of_float32_peak_%": round(100 * flops / seconds / 1e9 / peaks["float32"], 1),
               **where_time_goes(batch, bf16)}
        rows.append(row)
        print(f"batch {batch:3d} {'bf16' if bf16 else 'fp32'}: {seconds:.3f} s/epoch, "
              f"{row['samples_per_second']:.0f} samples/s, {row['gflops']:.0f} GFLOP/s "
              f"({row['share_of_float32_peak_%']:.0f}% of the float32 peak); time: {row['share_%']}")
bench.write({"time_stride": model_cfg.time_stride, "epoch_gflop": round(flops / 1e9, 2),
             "peak_gflops": {k: round(v, 1) for k, v in peaks.items()},
             "training_samples": len(train_set), "rows": rows})
