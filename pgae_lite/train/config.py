"""How a model is trained, :class:`TrainConfig` (paper Sec. 3, "Loss Function", and Sec. 4, "Training Details").

``TrainConfig`` holds what the training loop reads for every model: epochs and batches, the
optimiser and its schedule, the random draws of each step (signals, views, input noise), the loss
weights of the models trained on signals, the seed and the checkpoints. What only some trainings
read lives in a part beside its code, ``None`` in the plain recipe:

- ``supervision``: limited supervision, a share of the updates or of the samples paired
  (:class:`pgae_lite.train.supervision.SupervisionConfig`);
- ``phrasings``: the free-form variant's phrasings of every instruction
  (:class:`pgae_lite.freeform.phrasing_bank.PhrasingsConfig`).

The defaults are the ``book`` recipe; the paper's own settings are the ``paper`` profile in
:mod:`pgae_lite.config`. Every departure is marked ``# Deviation from paper:``; what it measured
to is on the book's results page (appendix A2), not in these comments.
"""
from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, fields

from pgae_lite.data.normaliser import check_vision_scaling
from pgae_lite.model.config import Part, check_part, flag, whole
from pgae_lite.model.signals import SIGNAL_PROBS
from pgae_lite.world.words import SIGNALS

#: The version of the recipe's meaning, saved in every checkpoint and hashed into every model's cache
#: key. Raise it when a change to a recipe's settings (a new option, a new default, an option that now
#: does something else) would make a model trained before mean something else: cached models then train
#: again, and an older checkpoint is refused with a clear message instead of being read wrong.
#: 3: the recipe's parts (ModelConfig.language, crossmodal, binding; TrainConfig.supervision, phrasings);
#: PRAE and PVAE trained by the one loop.
RECIPE_VERSION = 3
SCHEDULES = ("cosine", "constant")
TRAIN_PARTS = ("supervision", "phrasings")


def number(owner: str, name: str, value, low: float, high: float = math.inf, *, above: bool = False,
           optional: bool = False) -> None:
    """A ValueError unless ``value`` is a finite number in [low, high] (``above``: > low)."""
    if optional and value is None:
        return
    ok = not isinstance(value, bool) and isinstance(value, (int, float)) and math.isfinite(value) \
        and (value > low if above else value >= low) and value <= high
    if not ok:
        bound = f"> {low}" if above else f">= {low}"
        bound += f" and <= {high}" if high != math.inf else ""
        raise ValueError(f"{owner} {name} must be a number {bound}{' or None' if optional else ''}; got {value!r}")


def signal_probs_of(value) -> tuple[float, ...]:
    """``value`` as a tuple of floats when it holds one finite number >= 0 per signal (words.SIGNALS) and they sum
    to 1; else a ValueError (NaN, a text, a flag or a single number included)."""
    try:
        items = () if isinstance(value, (str, bytes, dict)) else tuple(value)
    except TypeError:                                   # a single number: not one per signal
        items = ()
    ok = len(items) == len(SIGNALS) and all(
        isinstance(q, numbers.Real) and not isinstance(q, bool) and 0 <= q <= 1 for q in items)   # NaN: False
    if not ok or abs(sum(items) - 1) > 1e-6:
        raise ValueError(f"signal_probs must be {len(SIGNALS)} non-negative numbers summing to 1 (finite: no NaN), "
                         f"one per signal in the order {', '.join(SIGNALS)}; got {value!r:.120}")
    return tuple(float(q) for q in items)


@dataclass(slots=True)     # a setting it does not have is an error, not a new attribute
class TrainConfig:
    """How a model is trained. Defaults are the ``book`` recipe."""

    # Deviation from paper: 300 epochs of batch 16 (paper: 6000 of batch 6 at a 300x smaller learning
    # rate). Its history (what was tried, what each change did) is on the book's results page (A2).
    epochs: int = 300
    batch_size: int = 16
    # Deviation from paper: each batch holds samples of one length (train.loop's batches); less time per epoch.
    length_batches: bool = True
    # Deviation from paper: AdamW 3e-3 with warm-up and cosine decay (paper: Adam 1e-5, constant).
    lr: float = 3e-3
    schedule: str = "cosine"            # "cosine" (warm-up, then cosine to 0) or "constant"
    warmup: float = 0.03                # fraction of steps of linear warm-up
    clip: float | None = 1.0            # gradient-norm clipping (paper: none)
    # Deviation from paper: decoupled weight decay (AdamW; paper: Adam, none). Smaller weights favour one
    # rule shared by all actions ("say the moved cube's colour") over a table of action-specific ones
    # (experiments/HISTORY.md: "weight decay 0.1").
    weight_decay: float = 0.1
    # Deviation from paper: a signal per sample (authors: one per batch).
    signals_per_sample: bool = True
    # How often each signal is drawn, in the order of words.SIGNALS (describe, execute,
    # repeat action, repeat both, repeat language); authors: 3/9, 3/9, 1/9, 1/9, 1/9.
    signal_probs: tuple[float, ...] = SIGNAL_PROBS
    # Deviation from paper: the language decoder is teacher-forced in training
    # (authors: it feeds back its own softmax, in training and at test time).
    teacher_language: bool = True
    # Deviation from paper: Gaussian noise of this std on the action encoder's inputs (vision and
    # joints, in model units [-1, 1]) in training: 0.1 on the visual features, 0.05 on the joints
    # (experiments/HISTORY.md: "input noise").
    input_noise: float = 0.1
    joint_input_noise: float | None = 0.05   # std on the joints part only; None: input_noise
    opposite_prob: float = 0.0          # chance that a sample shows the opposite agent's view
    # Deviation from paper: the visual features are whitened before the min/max scaling ("whiten",
    # see data.dataset.Normaliser; authors: "global", one min and max over all 30 features)
    # (experiments/HISTORY.md: "whitening").
    vision_scaling: str = "whiten"
    # The loss of the models trained on signals (model/loss.py): α, β and γ. PRAE and PVAE weigh their
    # terms as their authors do (model/prae.py, model/pvae.py).
    language_weight: float = 1.0        # α
    # Deviation from paper: β = 4 (paper: 1). A 0.5% joint error is a loss of about 1e-4, the words' ~0.1.
    action_weight: float = 4.0          # β
    # Deviation from paper: γ, the weight of the plan head's error (model/plan.py) inside the action loss
    # (paper: no plan head). Used when ModelConfig.plan_keyframes > 0.
    plan_weight: float = 4.0
    seed: int = 0
    max_train_samples: int | None = None  # a subset of the training split (smoke tests)
    checkpoint_every: int = 25          # epochs between checkpoints
    supervision: Part | None = None     # None: every step draws from signal_probs (see the module)
    phrasings: Part | None = None       # None: the dataset's descriptions only

    def __post_init__(self):
        number("TrainConfig", "lr", self.lr, 0, above=True)
        number("TrainConfig", "warmup", self.warmup, 0, 0.99)         # a fraction of the steps: 1 never leaves it
        number("TrainConfig", "clip", self.clip, 0, above=True, optional=True)
        for name in ("weight_decay", "input_noise", "language_weight", "action_weight", "plan_weight"):
            number("TrainConfig", name, getattr(self, name), 0)         # α, β, γ: a negative one maximises
        number("TrainConfig", "opposite_prob", self.opposite_prob, 0, 1)
        number("TrainConfig", "joint_input_noise", self.joint_input_noise, 0, optional=True)
        if self.schedule not in SCHEDULES:
            raise ValueError(f"unknown schedule {self.schedule!r}; the options are: {', '.join(SCHEDULES)}")
        for name in ("length_batches", "signals_per_sample", "teacher_language"):
            flag("TrainConfig", name, getattr(self, name))
        self.signal_probs = signal_probs_of(self.signal_probs)
        check_vision_scaling(self.vision_scaling)
        for name in ("epochs", "batch_size", "checkpoint_every"):
            whole("TrainConfig", name, getattr(self, name), 1)
        if self.max_train_samples is not None:
            whole("TrainConfig", "max_train_samples", self.max_train_samples, 1, " or None (all)")
        for name in TRAIN_PARTS:
            check_part("TrainConfig", name, getattr(self, name), self)

    def to_dict(self) -> dict:
        """Every setting as plain values, each part as its dict (None where unset): what a recipe saves."""
        d = {f.name: getattr(self, f.name) for f in fields(self)}
        return d | {name: None if d[name] is None else d[name].to_dict() for name in TRAIN_PARTS}


__all__ = ["RECIPE_VERSION", "SCHEDULES", "TRAIN_PARTS", "TrainConfig", "number", "signal_probs_of"]
