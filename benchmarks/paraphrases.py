"""Free-form instructions in the simulator: does PGAE-BERT do what a paraphrase asks?

    python benchmarks/paraphrases.py [CHECKPOINT] [--profile book] [--seed 0] [--limit 36] [--open-only]
                                     [--out benchmarks/out/paraphrases.json]

The paper (Sec. 3 and 5) says PGAE-BERT "has the potential to recognise unseen
natural language". Here every test episode is told one of the 108 held-out
paraphrases of its own instruction (``pgae_lite/paraphrases.tsv``, e.g. "Could
you shove the crimson cube forward in a hurry"; episode variation v gets the
paraphrase v mod 3 of its meaning, so each is used twice over the 216 episodes)
and executes it (:func:`pgae_lite.instructions.execute_paraphrases`): open loop,
the paper's execute (the decoder reads the recorded vision), and closed loop
(it reads what its own motion shows). Success is the simulator's check that
the named cube moved the named way; nRMSE is against the recorded joints of the
episode, the intended action.

CHECKPOINT is a PGAE-BERT checkpoint trained on the profile's simulated data;
without it, the profile's cached ``trained_pgae("PGAE-BERT", profile, seed)``
is used, and trained first if it is not cached (about 10 minutes on a 2-core
CPU in the ``book`` profile). ``--limit N`` takes N test episodes evenly spread.
Run it with ``OMP_NUM_THREADS=1``: the models are small, a second thread does not help.
"""
from __future__ import annotations

import argparse
import os
import time

import torch

from pgae_lite.closedloop import success_summary
from pgae_lite.config import get_profile
from pgae_lite.instructions import execute_paraphrases
from pgae_lite.language import LanguageError
from pgae_lite.pipeline import simulated_dataset, trained_cae, trained_pgae
from pgae_lite.train import load_model

from _report import write_report   # benchmarks/_report.py (the script's folder is on sys.path)

ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
ap.add_argument("checkpoint", nargs="?", help="a PGAE-BERT checkpoint (default: the profile's cached model)")
ap.add_argument("--profile", default="book", help="simulated dataset, CAE and model profile (default: book)")
ap.add_argument("--seed", type=int, default=0, help="seed of the cached model (without CHECKPOINT)")
ap.add_argument("--limit", type=int, default=None, help="this many test episodes, evenly spread (default: all)")
ap.add_argument("--open-only", action="store_true", help="only the paper's open-loop execute (fast)")
ap.add_argument("--out", default="benchmarks/out/paraphrases.json")
args = ap.parse_args()

torch.set_num_threads(int(os.environ.get("OMP_NUM_THREADS", "1")))
data = simulated_dataset(args.profile, "cpu", progress=False)
cae, _ = trained_cae(args.profile, "cpu", progress=False)
if args.checkpoint:
    model, normaliser, ckpt = load_model(args.checkpoint, "cpu", data)
    model_config = ckpt["profile"]["model"]
else:
    trained = trained_pgae("PGAE-BERT", args.profile, args.seed, device="cpu")
    model, normaliser, model_config = trained.model, trained.normaliser, trained.profile.to_dict()["model"]

t0 = time.perf_counter()
try:
    table = execute_paraphrases(model, cae, normaliser, data, limit=args.limit, closed=not args.open_only,
                                config=get_profile(args.profile).data)
except LanguageError as e:           # a PGAE checkpoint (LSTM language encoder): it cannot read them
    raise SystemExit(f"error: {e}") from None
seconds = time.perf_counter() - t0
summary = success_summary(table)

print(summary.round(2).to_string())
print(f"\n{len(table)} episodes in {seconds:.0f} s: {seconds / len(table):.2f} s per episode")
loop = "open" if args.open_only else "closed"
failed = table[~table[f"{loop}_passed"]]
if len(failed):
    print(f"\n{loop}-loop failures: {len(failed)} (the first 10; all of them in the JSON)")
    print(failed[["id", "meaning", "description", f"{loop}_reason"]].head(10).to_string(index=False))

write_report(args.out, table, summary, seconds,
             checkpoint=args.checkpoint or f"trained_pgae('PGAE-BERT', {args.profile!r}, seed={args.seed})",
             profile=args.profile, limit=args.limit, closed=not args.open_only, model=model_config)
