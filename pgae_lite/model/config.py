"""PGAE's architecture settings, :class:`ModelConfig` (paper Sec. 3; sizes from the authors' code).

The defaults are the ``book`` recipe; the paper's own settings are the ``paper`` profile in
:mod:`pgae_lite.config`, written as the book recipe with one override per line. Every departure
is marked ``# Deviation from paper:`` here; what it measured to is on the book's results page
(appendix A2), not in these comments.
"""
from __future__ import annotations

from dataclasses import dataclass

#: The language encoders a ModelConfig may name: the paper's LSTM (PGAE), the frozen pretrained
#: transformer (PGAE-BERT), and the transformer read through a trained attention pooling (not in the paper).
LANGUAGE_ENCODERS = ("lstm", "pretrained", "pretrained-attention")
CELLS = ("lstm", "peephole")
JOINT_FEEDBACKS = ("start", "predicted")
#: What joins the two modalities into h: PGAE's Gated Multimodal Unit, or PTAE's crossmodal transformer
#: (the words and signal attend to the action frames; pgae_lite.model.ptae).
BOTTLENECKS = ("gmu", "crossmodal-transformer")


def _whole(name: str, value, low: int, meaning: str = "") -> None:
    """A ValueError unless ``value`` is a whole number >= ``low`` (``meaning``: what a value means)."""
    if isinstance(value, bool) or not isinstance(value, int) or value < low:
        raise ValueError(f"ModelConfig {name} must be a whole number >= {low}{meaning}; got {value!r}")


@dataclass
class ModelConfig:
    """Architecture of PGAE (:class:`pgae_lite.model.pgae.PGAE`). Defaults are the ``book`` recipe.

    Sizes follow the authors' code: LSTMs of 100 units in 2 layers, h of 50.
    """

    units: int = 100
    layers: int = 2
    hidden: int = 50
    cell: str = "lstm"   # "peephole" = the paper's cell; "lstm" = fused nn.LSTM (faster)
    # Deviation from paper: "start" = the action decoder reads the start joints at every step instead of
    # its own previous prediction ("predicted", the paper's; see pgae.ActionDecoder).
    joint_feedback: str = "start"
    # Deviation from paper: one step of the action LSTMs covers 3 time steps: the encoder reads every 3rd
    # step, the decoder reads every 3rd frame and writes the next 3 poses, every pose (paper: 1). A third of
    # the LSTM steps per sample, with Table 1 kept; stride 4 lost joint precision (experiments/HISTORY.md).
    time_stride: int = 3
    # "lstm" = PGAE's language encoder; "pretrained" = PGAE-BERT's frozen transformer (bert/pretrained.py);
    # "pretrained-attention" = the same transformer with a trained attention pooling (bert/attention_pooling.py).
    language_encoder: str = "lstm"
    pretrained_model: str | None = None   # Hugging Face name or folder; None = the default shipped model
    # Not in the paper (which keeps the transformer frozen): with "pretrained-attention", free text reads
    # the transformer's top layer trained (bert/tuned_layer.py); the 869 fixed inputs stay frozen. With
    # "pretrained", every input reads it, mean-pooled: PVAE-BERT's fine-tuning, at the top layer
    # (bert/tuned_encoder.py).
    tuned_top_layer: bool = False
    # Deviation from paper: the GMU layer-normalises W_A f_act + b before its tanh (layers.GatedMultimodalUnit;
    # paper: no normalisation). Without it, on some seeds the unbounded cell states in f_act saturate A_h for
    # every sample early in training, and describe never learns: one sentence for every action
    # (experiments/HISTORY.md, "The describe collapse").
    gmu_norm: bool = True
    # Deviation from paper: a plan head reads h and predicts this many keyframes of the motion in training
    # (plan.PlanHead; 0 = none, the paper's). It makes h carry which cube the words mean in this scene, which
    # the recorded frames otherwise tell the decoder: without it the closed loop mostly moves the other cube.
    plan_keyframes: int = 10
    # "gmu" = PGAE; "crossmodal-transformer" = PTAE (model/ptae.py): the tokens and the frames enter one
    # transformer layer of ``heads`` heads and a feed-forward of ``feedforward`` units, whose width is
    # ``hidden``. The book's PTAE is 128 wide (config.TRAININGS); PTAE's authors: 4 heads, 256, 1024, 0.25.
    bottleneck: str = "gmu"
    heads: int = 4
    # Deviation from paper: a feed-forward of 512 (PTAE: 1024), no dropout (PTAE: 0.25), and the frames read
    # with their positions (PTAE: none; push and pull visit the same poses in opposite orders). Each change
    # and what it did on the authors' data: benchmarks/ptae_recipe.py (results/ptae_recipe.json, A2).
    feedforward: int = 512
    dropout: float = 0.0
    frame_positions: bool = True

    def __post_init__(self):
        for name in ("units", "layers", "hidden"):
            _whole(name, getattr(self, name), 1)
        if self.cell not in CELLS:
            raise ValueError(f"unknown cell {self.cell!r}; the options are: {', '.join(CELLS)}")
        if self.joint_feedback not in JOINT_FEEDBACKS:
            raise ValueError(f"unknown joint_feedback {self.joint_feedback!r}; the options are: "
                             f"{', '.join(JOINT_FEEDBACKS)}")
        if not isinstance(self.gmu_norm, bool):
            raise ValueError(f"gmu_norm must be True or False; got {self.gmu_norm!r}")
        _whole("plan_keyframes", self.plan_keyframes, 0, " (0 = no plan head, the paper's)")
        _whole("time_stride", self.time_stride, 1, " (1 = every step, the paper's)")
        if self.bottleneck not in BOTTLENECKS:
            raise ValueError(f"unknown bottleneck {self.bottleneck!r}; the options are: {', '.join(BOTTLENECKS)}")
        _whole("heads", self.heads, 1)
        _whole("feedforward", self.feedforward, 1)
        if isinstance(self.dropout, bool) or not isinstance(self.dropout, (int, float)) or not 0 <= self.dropout < 1:
            raise ValueError(f"ModelConfig dropout must be a number in [0, 1); got {self.dropout!r}")
        if not isinstance(self.frame_positions, bool):
            raise ValueError(f"frame_positions must be True or False; got {self.frame_positions!r}")
        if self.bottleneck == "crossmodal-transformer":
            if self.hidden % self.heads:
                raise ValueError(f"the crossmodal transformer splits its width (hidden={self.hidden}) among "
                                 f"{self.heads} heads: hidden must be a multiple of heads")
            if self.language_encoder != "lstm":
                raise ValueError(f"the crossmodal transformer reads the words as tokens itself; "
                                 f"language_encoder={self.language_encoder!r} needs bottleneck='gmu'")
        if self.language_encoder not in LANGUAGE_ENCODERS:
            raise ValueError(f"unknown language_encoder {self.language_encoder!r}; "
                             f"the options are: {', '.join(LANGUAGE_ENCODERS)}")
        if not isinstance(self.tuned_top_layer, bool):
            raise ValueError(f"tuned_top_layer must be True or False; got {self.tuned_top_layer!r}")
        if self.tuned_top_layer and self.language_encoder == "lstm":
            raise ValueError(f"tuned_top_layer needs a pretrained language encoder ('pretrained' or "
                             f"'pretrained-attention'); got language_encoder={self.language_encoder!r}")

    @property
    def state_dim(self) -> int:
        return 2 * self.layers * self.units  # [c_0; h_0; c_1; h_1]


__all__ = ["BOTTLENECKS", "CELLS", "JOINT_FEEDBACKS", "LANGUAGE_ENCODERS", "ModelConfig"]
