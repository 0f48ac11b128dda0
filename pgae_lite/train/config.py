"""How PGAE is trained, :class:`TrainConfig` (paper Sec. 3, "Loss Function", and Sec. 4, "Training Details").

The defaults are the ``book`` recipe; the paper's own settings are the ``paper`` profile in
:mod:`pgae_lite.config`. Every departure is marked ``# Deviation from paper:``; what it measured
to is on the book's results page (appendix A2), not in these comments.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from pgae_lite.data.dataset import check_vision_scaling
from pgae_lite.model.config import ModelConfig
from pgae_lite.model.signals import SIGNAL_PROBS
from pgae_lite.util.storage import CheckpointMismatchError
from pgae_lite.world.words import SIGNALS

#: The version of the recipe's meaning, saved in every checkpoint and hashed into every model's cache
#: key. Raise it when a change to ModelConfig or TrainConfig (a new option, a new default, an option
#: that now does something else) would make a model trained before mean something else: cached models
#: then train again, and an older checkpoint is refused with a clear message instead of being read wrong.
RECIPE_VERSION = 2
#: The signals that take a description, and so may read phrasings (TrainConfig.phrasing_signals).
PHRASING_SIGNALS = ("execute", "repeat both", "repeat language")
PHRASING_WORDS = ("all", "held-out")
SCHEDULES = ("cosine", "constant")


def _number(name: str, value, low: float, high: float = math.inf, *, above: bool = False,
            optional: bool = False) -> None:
    """A ValueError unless ``value`` is a finite number in [low, high] (``above``: > low)."""
    if optional and value is None:
        return
    ok = not isinstance(value, bool) and isinstance(value, (int, float)) and math.isfinite(value) \
        and (value > low if above else value >= low) and value <= high
    if not ok:
        bound = f"> {low}" if above else f">= {low}"
        bound += f" and <= {high}" if high != math.inf else ""
        raise ValueError(f"TrainConfig {name} must be a number {bound}{' or None' if optional else ''}; "
                         f"got {value!r}")


@dataclass
class TrainConfig:
    """How PGAE is trained. Defaults are the ``book`` recipe."""

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
    language_weight: float = 1.0        # α
    # Deviation from paper: β = 4 (paper: 1). A 0.5% joint error is a loss of about 1e-4, the words' ~0.1.
    action_weight: float = 4.0          # β
    # Deviation from paper: γ, the weight of the plan head's error (model/plan.py) inside the action loss
    # (paper: no plan head). Used when ModelConfig.plan_keyframes > 0.
    plan_weight: float = 4.0
    # Not in the paper: K > 0 = samples with a description read, with probability phrasing_prob, one
    # of K sentences saying it in other words (bert/phrasing_bank.py; PGAE-BERT only). 0 = the dataset's
    # descriptions.
    phrasings: int = 0
    # Chosen on generated validation sentences (experiments/validation_readback.py), never on the test
    # paraphrases (experiments/HISTORY.md).
    phrasing_prob: float = 0.75
    # "all": the phrasings use the whole lexicon; "held-out": less phrase_lexicon.held_out_words(), so
    # that a test sentence with one of those words says something never trained on.
    phrasing_words: str = "all"
    # Not in the paper: the signals whose samples read phrasings (of execute, repeat both, repeat language).
    phrasing_signals: tuple[str, ...] = PHRASING_SIGNALS
    # Limited supervision (PTAE paper; train/supervision.py): a share in (0, 1] of the updates is paired
    # (the PTAE authors' reading), or of the training samples, a fixed labelled subset. None: the recipe's draws.
    paired_share: float | None = None
    labelled_share: float | None = None
    seed: int = 0
    max_train_samples: int | None = None  # a subset of the training split (smoke tests)
    checkpoint_every: int = 25          # epochs between checkpoints

    def __post_init__(self):
        _number("lr", self.lr, 0, above=True)
        _number("warmup", self.warmup, 0, 0.99)                 # a fraction of the steps: 1 never leaves it
        _number("clip", self.clip, 0, above=True, optional=True)
        _number("weight_decay", self.weight_decay, 0)
        _number("opposite_prob", self.opposite_prob, 0, 1)
        _number("input_noise", self.input_noise, 0)
        for name in ("paired_share", "labelled_share"):
            _number(name, getattr(self, name), 0, 1, above=True, optional=True)
        if self.paired_share is not None and self.labelled_share is not None:
            raise ValueError("TrainConfig takes one reading of limited supervision: paired_share (a share of the "
                             "updates) or labelled_share (a fixed share of the samples), not both")
        _number("joint_input_noise", self.joint_input_noise, 0, optional=True)
        for name in ("language_weight", "action_weight", "plan_weight"):   # α, β, γ: a negative one maximises
            _number(name, getattr(self, name), 0)
        if self.schedule not in SCHEDULES:
            raise ValueError(f"unknown schedule {self.schedule!r}; the options are: {', '.join(SCHEDULES)}")
        for name in ("length_batches", "signals_per_sample", "teacher_language"):
            if not isinstance(getattr(self, name), bool):
                raise ValueError(f"TrainConfig {name} must be True or False; got {getattr(self, name)!r}")
        probs = tuple(float(q) for q in self.signal_probs)
        if len(probs) != len(SIGNALS) or min(probs) < 0 or abs(sum(probs) - 1) > 1e-6:
            raise ValueError(f"signal_probs must be {len(SIGNALS)} non-negative numbers summing to 1, one per "
                             f"signal in the order {', '.join(SIGNALS)}; got {self.signal_probs}")
        self.signal_probs = probs
        check_vision_scaling(self.vision_scaling)
        if isinstance(self.phrasings, bool) or not hasattr(self.phrasings, "__index__") or self.phrasings < 0:
            raise ValueError(f"TrainConfig phrasings must be a whole number >= 0 (0: the dataset's "
                             f"descriptions only); got {self.phrasings!r}")
        if isinstance(self.phrasing_prob, bool) or not isinstance(self.phrasing_prob, (int, float)) \
                or not 0 < self.phrasing_prob <= 1:
            raise ValueError(f"TrainConfig phrasing_prob must be a number in (0, 1], the chance that a sample "
                             f"with a description reads a phrasing instead; got {self.phrasing_prob!r}")
        self.phrasing_signals = tuple(self.phrasing_signals)
        if not self.phrasing_signals or not set(self.phrasing_signals) <= set(PHRASING_SIGNALS):
            raise ValueError(f"TrainConfig phrasing_signals must name one or more of "
                             f"{', '.join(PHRASING_SIGNALS)}; got {self.phrasing_signals!r}")
        if self.phrasing_words not in PHRASING_WORDS:
            raise ValueError(f"TrainConfig phrasing_words must be 'all' or 'held-out'; got {self.phrasing_words!r}")
        for name in ("epochs", "batch_size", "checkpoint_every", "max_train_samples"):
            value = getattr(self, name)
            if name == "max_train_samples" and value is None:
                continue
            if isinstance(value, bool) or not hasattr(value, "__index__") or value < 1:
                also = " or None (all)" if name == "max_train_samples" else ""
                raise ValueError(f"TrainConfig {name} must be a whole number >= "
                                 f"1{also}; got {value!r}")


def saved_model_config(recipe: dict, path) -> ModelConfig:
    """The :class:`~pgae_lite.model.config.ModelConfig` of a checkpoint's saved recipe
    (``Profile.to_dict()``), if it was trained with this :data:`RECIPE_VERSION`; else a
    :class:`~pgae_lite.util.storage.CheckpointMismatchError` that says so."""
    version = recipe.get("recipe_version") if isinstance(recipe, dict) else None
    if version != RECIPE_VERSION:
        raise CheckpointMismatchError(
            f"{path} was trained with recipe version {version or 'before versions'}; this pgae_lite reads "
            f"version {RECIPE_VERSION} (an option's meaning or default changed since): train the model again")
    return ModelConfig(**recipe["model"])


__all__ = ["PHRASING_SIGNALS", "PHRASING_WORDS", "RECIPE_VERSION", "TrainConfig", "saved_model_config"]
