"""Limited supervision: only some training steps pair an action with its description (PTAE paper, Sec. 4).

A signal that reads one modality and writes the other (describe, execute) or both (repeat
both) needs the pair; repeat action and repeat language need one modality only, so they
learn from unpaired data. PTAE's authors ask how the models fare when few training steps
are paired, and their code reads "x% supervised" as a share of *updates*: each batch is
paired with probability x, while the loader reshuffles every epoch, so every sample is seen
paired now and then. A fixed labelled subset of x% of the *samples* is the other reading::

    | TrainConfig.supervision            | a paired step                   | the other steps                     |
    |------------------------------------|---------------------------------|-------------------------------------|
    | SupervisionConfig(x, of="updates") | a batch, with probability x     | the batch: repeat action / language |
    | SupervisionConfig(x, of="samples") | a sample of the fixed x% subset | the other samples: the same two     |
    | None (default)                     | every sample draws from signal_probs (7/9 of the draws paired)        |

Within each kind a signal keeps its weight in ``TrainConfig.signal_probs``: describe 3/7,
execute 3/7, repeat both 1/7 when paired; repeat action and repeat language 1/2 each otherwise.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import torch

from pgae_lite.model.config import Part
from pgae_lite.model.signals import DESCRIBE, EXECUTE, REPEAT_ACTION, REPEAT_BOTH, REPEAT_LANGUAGE, sample_signals
from pgae_lite.world.words import SIGNALS

#: What a share counts: the PTAE authors' reading (a share of the updates), or a fixed labelled subset.
READINGS = ("updates", "samples")
PAIRED = (DESCRIBE, EXECUTE, REPEAT_BOTH)           # need the action and its description together
UNIMODAL = (REPEAT_ACTION, REPEAT_LANGUAGE)          # need one of them only


@dataclass(frozen=True)
class SupervisionConfig(Part):
    """Limited supervision (``TrainConfig.supervision``): a ``share`` in (0, 1] of the updates, or of the training
    samples, is paired (see the module)."""

    kind: ClassVar[str] = "supervision"
    slot: ClassVar[str] = "supervision"
    share: float
    of: str = "updates"

    def __post_init__(self):
        ok = not isinstance(self.share, bool) and isinstance(self.share, (int, float)) and 0 < self.share <= 1
        if not ok:
            raise ValueError(f"SupervisionConfig share must be a number in (0, 1], the paired share; "
                             f"got {self.share!r}")
        if self.of not in READINGS:
            raise ValueError(f"SupervisionConfig of must be one of {', '.join(READINGS)} (a share of the updates, "
                             f"or a fixed share of the samples); got {self.of!r}")

    def check(self, owner) -> None:
        """Refuse ``owner``'s (a TrainConfig's) signal_probs when they give no weight to the paired signals or to
        the unimodal ones: a paired step, or an unpaired one, would have nothing to draw."""
        for keep in (PAIRED, UNIMODAL):
            restricted(owner.signal_probs, keep)


def restricted(probs: tuple[float, ...], keep: tuple[int, ...]) -> tuple[float, ...]:
    """``probs`` with every signal outside ``keep`` set to 0, renormalised to sum to 1."""
    kept = [q if i in keep else 0.0 for i, q in enumerate(probs)]
    total = sum(kept)
    if total <= 0:
        kind = "paired" if keep == PAIRED else "unimodal" if keep == UNIMODAL else "kept"
        raise ValueError(f"signal_probs give no weight to any of the signals {_named(keep)} (the {kind} ones), so "
                         f"limited supervision would train on no {kind} step; give weight to at least one of them, "
                         f"and to one of the {'unimodal' if keep == PAIRED else 'paired'} signals "
                         f"({_named(UNIMODAL if keep == PAIRED else PAIRED)})")
    return tuple(q / total for q in kept)


def _named(signals: tuple[int, ...]) -> str:
    """The names of ``signals`` (indices into words.SIGNALS), joined."""
    return ", ".join(SIGNALS[i] for i in signals)


def labelled_samples(count: int, share: float, seed: int) -> torch.Tensor:
    """Which of ``count`` training samples are labelled (paired), (count,) bool: round(share · count) of
    them (at least 1), drawn once from ``seed`` with a generator of their own."""
    chosen = torch.randperm(count, generator=torch.Generator().manual_seed(seed))[:max(1, round(share * count))]
    return torch.zeros(count, dtype=torch.bool).index_fill_(0, chosen, True)


def draw_signals(size: int, gen: torch.Generator, cfg, labelled: torch.Tensor | None = None) -> torch.Tensor:
    """The signals of one batch of ``size`` samples under ``cfg`` (a TrainConfig), (size,).

    ``labelled`` (size,) bool: which of the batch's samples are in the labelled subset (a share
    of the samples). Without ``cfg.supervision``, exactly the recipe's draws.
    """
    supervision = cfg.supervision
    if supervision is not None and supervision.of == "updates":      # a share of the updates is paired
        paired = torch.rand(1, generator=gen).item() < supervision.share
        probs = restricted(cfg.signal_probs, PAIRED if paired else UNIMODAL)
        return sample_signals(size, gen, cfg.signals_per_sample, probs)
    signals = sample_signals(size, gen, cfg.signals_per_sample, cfg.signal_probs)
    if supervision is None:
        return signals
    unimodal = sample_signals(size, gen, cfg.signals_per_sample, restricted(cfg.signal_probs, UNIMODAL))
    return torch.where(labelled, signals, unimodal)         # an unlabelled sample: one modality at a time


__all__ = ["PAIRED", "READINGS", "SupervisionConfig", "UNIMODAL", "draw_signals", "labelled_samples", "restricted"]
