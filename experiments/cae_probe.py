"""Linear probe: do the CAE's first-frame features name the left and right cube colours?

    python experiments/cae_probe.py [--profile book]

Fits a multinomial logistic regression (one linear layer, L-BFGS) from the 30
visual features of an episode's first frame to the colour of the left cube,
and another to the colour of the right cube, on the training split; reports
accuracy on the test split, for NICO's own view and for the opposite view.
Uses the cached dataset (``pgae_lite.runs.data.simulated_dataset``). Appends a
JSON line to ``experiments/out/cae_probe.jsonl``.
"""
import argparse
import json
from pathlib import Path

import numpy as np
import torch

from pgae_lite.config import get_profile
from pgae_lite.runs.data import simulated_dataset
from pgae_lite.world.words import COLOURS


def probe(x_train: np.ndarray, y_train: np.ndarray, x_test: np.ndarray, y_test: np.ndarray) -> float:
    """Test accuracy (%) of a linear classifier fitted on standardised features."""
    mean, std = x_train.mean(0), x_train.std(0) + 1e-6
    xs, xt = (torch.tensor((x - mean) / std, dtype=torch.float64) for x in (x_train, x_test))
    ys = torch.tensor(y_train)
    torch.manual_seed(0)
    layer = torch.nn.Linear(xs.shape[1], len(COLOURS)).double()
    opt = torch.optim.LBFGS(layer.parameters(), max_iter=500, line_search_fn="strong_wolfe")

    def closure():
        opt.zero_grad()
        loss = torch.nn.functional.cross_entropy(layer(xs), ys) + 1e-4 * layer.weight.pow(2).sum()
        loss.backward()
        return loss
    opt.step(closure)
    with torch.no_grad():
        return 100 * float((layer(xt).argmax(1).numpy() == y_test).mean())


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--profile", default="book")
    args = ap.parse_args()
    ds = simulated_dataset(get_profile(args.profile))
    left = np.array([COLOURS.index(a.split("+")[0]) for a in ds.arrangement])
    right = np.array([COLOURS.index(a.split("+")[1]) for a in ds.arrangement])
    train, test = ~ds.is_test, ds.is_test
    row = {"profile": args.profile, "train": int(train.sum()), "test": int(test.sum())}
    for view in ("vision", "vision_opposite"):
        first = getattr(ds, view)[:, 0]                                    # (N, 30) first frame
        for side, y in (("left", left), ("right", right)):
            row[f"{view}_{side}_acc"] = round(probe(first[train], y[train], first[test], y[test]), 2)
    print(json.dumps(row))
    out = Path(__file__).parent / "out"
    out.mkdir(exist_ok=True)
    with open(out / "cae_probe.jsonl", "a") as f:
        f.write(json.dumps(row) + "\n")


if __name__ == "__main__":
    main()
