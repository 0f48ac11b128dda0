"""The models' architecture settings, :class:`ModelConfig` (paper Sec. 3; sizes from the authors' code).

``ModelConfig`` holds what every model of the book reads: its LSTMs, the size of its shared
representation, its action decoder's feedback and time stride, and the two options of the paper's
bottleneck and plan head. What only some models read lives in a part beside their code, ``None`` in
the plain recipe (PGAE):

- ``language``: a pretrained language encoder in place of the LSTM over one-hot words: PGAE-BERT's
  (:class:`pgae_lite.bert.config.PretrainedConfig`) or the free-form variant's
  (:class:`pgae_lite.freeform.attention_pooling.AttentionConfig`);
- ``crossmodal``: PTAE's crossmodal transformer in place of the GMU (:class:`pgae_lite.model.ptae.CrossmodalConfig`);
- ``binding``: PRAE's and PVAE's two autoencoders bound by a loss (:class:`pgae_lite.model.prae.BindingConfig`).

Every part is a :class:`Part`: frozen, checked where it is made, written into a recipe's dict with
its ``kind``. The defaults are the ``book`` recipe; the paper's own settings are the ``paper``
profile in :mod:`pgae_lite.config`. Every departure is marked ``# Deviation from paper:`` here;
what it measured to is on the book's results page (appendix A2), not in these comments.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass, fields
from typing import ClassVar

CELLS = ("lstm", "peephole")
JOINT_FEEDBACKS = ("start", "predicted")
#: The optional parts of a ModelConfig, each None or a Part.
PARTS = ("language", "crossmodal", "binding")
#: h of the plain recipe (PGAE's GMU output), as in the authors' code.
HIDDEN = 50


def whole(owner: str, name: str, value, low: int, meaning: str = "") -> None:
    """A ValueError unless ``value`` is a whole number >= ``low`` (``meaning``: what a value means)."""
    if isinstance(value, bool) or not isinstance(value, int) or value < low:
        raise ValueError(f"{owner} {name} must be a whole number >= {low}{meaning}; got {value!r}")


def check_part(owner: str, name: str, part, config) -> None:
    """A ValueError unless ``part`` is None or a :class:`Part` whose slot is ``name`` and that can go with the rest
    of ``config`` (the config holding it, ``owner``)."""
    if part is None:
        return
    if not isinstance(part, Part) or part.slot != name:
        what = f"{type(part).__name__}, the settings of {part.slot}" if isinstance(part, Part) else repr(part)
        raise ValueError(f"{owner} {name} must be None or the settings of its {name} (see the module "
                         f"pgae_lite.{'model' if owner == 'ModelConfig' else 'train'}.config); got {what}")
    part.check(config)


def flag(owner: str, name: str, value) -> None:
    """A ValueError unless ``value`` is True or False."""
    if not isinstance(value, bool):
        raise ValueError(f"{owner} {name} must be True or False; got {value!r}")


@dataclass(frozen=True)
class Part:
    """An optional part of a recipe, beside the code that reads it: its ``kind`` names it in a recipe's dict, its
    ``slot`` says which setting of a config holds it (``ModelConfig.language``, ``TrainConfig.phrasings``, ...)."""

    kind: ClassVar[str] = "part"
    slot: ClassVar[str] = ""
    #: The width h (ModelConfig.hidden) a model with this part has when its ModelConfig does not give one
    #: (None: the plain recipe's, :data:`HIDDEN`).
    hidden: ClassVar[int | None] = None

    def check(self, owner) -> None:
        """Raise a ValueError if this part cannot go with the rest of ``owner`` (the config holding it)."""

    def to_dict(self) -> dict:
        return {"kind": self.kind, **asdict(self)}


@dataclass(slots=True)     # a setting it does not have is an error, not a new attribute
class ModelConfig:
    """Architecture of PGAE and its family (:func:`pgae_lite.model.build.build_model`). Defaults: the
    ``book`` recipe's PGAE. Sizes follow the authors' code: LSTMs of 100 units in 2 layers, h of 50."""

    units: int = 100
    layers: int = 2
    # h: the GMU's output (PGAE), the transformer's width (PTAE), each code (PRAE, PVAE). None: the width its
    # parts are built for (Part.hidden: PTAE's 128, which its 4 heads divide), else HIDDEN (50).
    hidden: int | None = None
    cell: str = "lstm"   # "peephole" = the paper's cell; "lstm" = fused nn.LSTM (faster)
    # Deviation from paper: "start" = the action decoder reads the start joints at every step instead of
    # its own previous prediction ("predicted", the paper's; see pgae.ActionDecoder).
    joint_feedback: str = "start"
    # Deviation from paper: one step of the action LSTMs covers 3 time steps: the encoder reads every 3rd
    # step, the decoder reads every 3rd frame and writes the next 3 poses, every pose (paper: 1). A third of
    # the LSTM steps per sample, with Table 1 kept; stride 4 lost joint precision (experiments/HISTORY.md).
    time_stride: int = 3
    # Deviation from paper: the GMU layer-normalises W_A f_act + b before its tanh (layers.GatedMultimodalUnit;
    # paper: no normalisation). Without it, on some seeds the unbounded cell states in f_act saturate A_h for
    # every sample early in training, and describe never learns: one sentence for every action
    # (experiments/HISTORY.md, "The describe collapse"). Read by the GMU only.
    gmu_norm: bool = True
    # Deviation from paper: a plan head reads h and predicts this many keyframes of the motion in training
    # (plan.PlanHead; 0 = none, the paper's). It makes h carry which cube the words mean in this scene, which
    # the recorded frames otherwise tell the decoder: without it the closed loop mostly moves the other cube.
    # PRAE and PVAE have none (their recipes set 0).
    plan_keyframes: int = 10
    language: Part | None = None      # None: PGAE's LSTM over one-hot words (see the module)
    crossmodal: Part | None = None    # None: the GMU
    binding: Part | None = None       # None: one model for every signal

    def __post_init__(self):
        if self.hidden is None:          # a default that works with every part given (PTAE's heads divide it)
            self.hidden = next((part.hidden for part in (getattr(self, name) for name in PARTS)
                                if isinstance(part, Part) and part.hidden), HIDDEN)
        for name in ("units", "layers", "hidden"):
            whole("ModelConfig", name, getattr(self, name), 1)
        if self.cell not in CELLS:
            raise ValueError(f"unknown cell {self.cell!r}; the options are: {', '.join(CELLS)}")
        if self.joint_feedback not in JOINT_FEEDBACKS:
            raise ValueError(f"unknown joint_feedback {self.joint_feedback!r}; the options are: "
                             f"{', '.join(JOINT_FEEDBACKS)}")
        flag("ModelConfig", "gmu_norm", self.gmu_norm)
        whole("ModelConfig", "plan_keyframes", self.plan_keyframes, 0, " (0 = no plan head, the paper's)")
        whole("ModelConfig", "time_stride", self.time_stride, 1, " (1 = every step, the paper's)")
        for name in PARTS:
            check_part("ModelConfig", name, getattr(self, name), self)
        if self.crossmodal is not None and self.binding is not None:
            raise ValueError("a model has one bottleneck: PTAE's crossmodal transformer (crossmodal) or PRAE's "
                             "and PVAE's binding loss (binding), not both")

    @property
    def state_dim(self) -> int:
        return 2 * self.layers * self.units  # [c_0; h_0; c_1; h_1]

    def to_dict(self) -> dict:
        """Every setting as plain values, each part as its dict (None where unset): what a recipe saves."""
        d = {f.name: getattr(self, f.name) for f in fields(self)}
        return d | {name: None if d[name] is None else d[name].to_dict() for name in PARTS}


__all__ = ["CELLS", "HIDDEN", "JOINT_FEEDBACKS", "ModelConfig", "PARTS", "Part", "check_part", "flag", "whole"]
