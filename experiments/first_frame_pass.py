"""Exploration: make h carry which cube to move, for the closed loop (experiments/HISTORY.md, "The closed loop
moves the other cube").

    python experiments/first_frame_pass.py [--share 0.5] [--weight 0.25] [--detach] [--episodes 72]
        -- --sim --epochs 300 --seed 0 --save DIR        (then any option of explore_recipe.py)

Trains as ``explore_recipe.py`` does, with one addition to the loss: for ``share`` of the samples
whose action decoder reads recorded frames (execute, repeat action, repeat both), the decoder runs
a second time from the same h reading only the first frame, v_0, at every step, and

    L += β · weight · MSE(joints decoded from v_0 alone, recorded joints)

``--detach`` holds the decoder's weights fixed in that pass, so its gradient reaches h only.
With ``--sim --save DIR`` it then runs ``episodes`` test episodes open and closed loop
(:func:`pgae_lite.robot.closedloop.compare`). It patches PGAE's forward pass and the loss its
training reads (:func:`pgae_lite.model.loss.pgae_loss`), which is why it is an experiment and not
an option of the package.
"""
import argparse
import sys
from pathlib import Path

import torch

import pgae_lite.model.loss as losses
from pgae_lite.model.pgae import PGAE
from pgae_lite.model.signals import EXECUTE, REPEAT_ACTION, REPEAT_BOTH

sys.path.insert(0, str(Path(__file__).parent))
import explore_recipe  # noqa: E402


def install(share: float, weight: float, detach: bool) -> None:
    forward, loss = PGAE.forward, losses.pgae_loss

    def forward_with_first_frame(self, batch, *args, **kwargs):
        out = forward(self, batch, *args, **kwargs)
        if not self.training:                                            # evaluation: one pass only
            return out
        s = batch.signal
        reads_frames = (s == EXECUTE) | (s == REPEAT_ACTION) | (s == REPEAT_BOTH)
        rows = torch.nonzero(reads_frames & (torch.rand(len(s), device=s.device) < share))[:, 0]
        if len(rows):
            vision = batch.dec_vision[rows]                                  # (n, T-1, 30)
            inputs = (out["h"][rows], vision[:, :1].expand_as(vision), batch.start_joints[rows])
            steps = dict(steps=batch.joint_mask[rows].sum(1))
            decoder = self.action_decoder
            if detach:
                fixed = {k: p.detach() for k, p in decoder.named_parameters()}
                out["first_frame"] = torch.func.functional_call(decoder, fixed, inputs, steps)
            else:
                out["first_frame"] = decoder(*inputs, **steps)
            out["first_frame_rows"] = rows
        return out

    def loss_with_first_frame(out, batch, weights, alpha=1.0, beta=1.0):
        total, lang, act = loss(out, batch, weights, alpha, beta)
        if "first_frame" in out:
            rows = out["first_frame_rows"]
            m = batch.joint_mask[rows].float()[..., None]                    # (n, T-1, 1)
            err = ((out["first_frame"] - batch.joint_target[rows]) ** 2 * m).sum() / (m.sum() * 5)
            total = total + beta * weight * err
        return total, lang, act

    PGAE.forward, losses.pgae_loss = forward_with_first_frame, loss_with_first_frame


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--share", type=float, default=0.5)
    ap.add_argument("--weight", type=float, default=0.25)
    ap.add_argument("--detach", action="store_true")
    ap.add_argument("--episodes", type=int, default=72, help="closed-loop test episodes (--sim --save only)")
    ours, rest = ap.parse_known_args()
    rest = [a for a in rest if a != "--"]
    install(ours.share, ours.weight, ours.detach)
    sys.argv = [sys.argv[0], *rest]
    explore_recipe.main()
    if "--sim" in rest and "--save" in rest:
        from pgae_lite.config import get_profile
        from pgae_lite.robot.closedloop import compare, success_summary
        from pgae_lite.runs.data import simulated_dataset, trained_cae
        from pgae_lite.runs.pipeline import load_model
        profile = get_profile("book")                                     # resolved once, here
        data = simulated_dataset(profile, progress=False)
        cae, _ = trained_cae(profile, progress=False)
        folder = Path(rest[rest.index("--save") + 1])
        model, normaliser, _ = load_model(next(folder.glob("*.pt")), dataset=data)
        table = compare(model, cae, normaliser, data, limit=ours.episodes, progress=False)
        print(success_summary(table).round(2).to_string())


if __name__ == "__main__":
    main()
