"""Exploration: when does a closed-loop execution decide its fate? Recorded frames for the first K steps.

    python experiments/recorded_first_steps.py CHECKPOINT [--episodes 24] [--steps 0 6 12 20 30]

Runs test episodes of our simulated data (book profile) in closed loop, as
:func:`pgae_lite.robot.closedloop.closed_loop` does, except that for the first K time
steps the decoder reads the *recorded* frame instead of its own camera's (the
arm still moves as the model says). If success jumps once K covers the first
steps, the decoder decides in those steps what it does later: which cube it
goes for. Prints the success rate per K. The checkpoint is one trained on the
book profile's simulated data (e.g. from ``experiments/explore_recipe.py --sim --save``
or the cache's ``pgae/*/checkpoint.pt``).
"""
import argparse

import numpy as np
import torch

from pgae_lite.cae import extract_features
from pgae_lite.config import get_profile
from pgae_lite.data.dataset import description_text
from pgae_lite.robot.closedloop import _drive, _start, execute_batch, spread, variation_of
from pgae_lite.runs.data import simulated_dataset, trained_cae
from pgae_lite.runs.pipeline import load_model
from pgae_lite.sim.record import shared_simulation

PROFILE = get_profile("book")          # resolved once, here


@torch.no_grad()
def run(model, cae, normaliser, test, tensors, i: int, recorded_steps: int) -> bool:
    """Episode i of the test split in closed loop, reading the recorded frames for t < recorded_steps."""
    config = PROFILE.data
    pattern, variation, length = int(test.pattern[i]), variation_of(test.ids[i]), int(test.lengths[i])
    words = tuple(description_text(test.descriptions[i, i % 8]).split())
    sim = shared_simulation(config.sim, config.the_world)
    frame = _start(sim, config, pattern, variation, render=True)

    def features(f):
        return torch.from_numpy(normaliser.vision_to_model(extract_features(cae, f[None])))

    v = features(frame)
    j0 = torch.from_numpy(normaliser.joints_to_model(sim.joints()))[None].float()
    h, _ = model.encode(execute_batch(v[0], j0[0], words))
    decoder, start, k = model.action_decoder, j0, model.cfg.time_stride
    state, j = decoder.begin(h), j0
    for t in range(0, length - 1, k):
        seen = tensors["vision"][i, t][None] if t < recorded_steps else v
        j, state = decoder.step(state, seen, j, start)
        for pose in j.reshape(k, 1, -1)[:length - 1 - t]:
            _, frame = _drive(sim, normaliser.joints_to_data(pose)[0].numpy(), True, render=True)
        v = features(frame)
    return sim.check().passed


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("checkpoint")
    ap.add_argument("--episodes", type=int, default=24)
    ap.add_argument("--steps", type=int, nargs="+", default=[0, 6, 12, 20, 30])
    a = ap.parse_args()
    torch.set_num_threads(1)
    data = simulated_dataset(PROFILE, progress=False)
    cae, _ = trained_cae(PROFILE, progress=False)
    model, normaliser, _ = load_model(a.checkpoint, dataset=data)
    test = data.split("test")
    tensors = normaliser.tensors(test)
    rows = spread(len(test), a.episodes)
    for steps in a.steps:
        passed = [run(model, cae, normaliser, test, tensors, int(i), steps) for i in rows]
        print(f"recorded frames for the first {steps:3d} steps: {100 * np.mean(passed):5.1f}% "
              f"of {len(rows)} episodes passed", flush=True)


if __name__ == "__main__":
    main()
