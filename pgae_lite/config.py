"""Profiles and recipes, in one place: the paper's Sec. 4 training settings and Table 1's rows.

A profile is a whole run: what to record (:class:`~pgae_lite.data.simulated.DatasetConfig`),
the CAE (:class:`~pgae_lite.cae.CAEConfig`), the model (:class:`ModelConfig`), its
training (:class:`TrainConfig`) and how much the chapters do (:class:`ChapterSettings`).
Three are built in:

- ``smoke``: seconds; for CI and for checking that a notebook runs.
- ``book`` (default): minutes on a 2-core laptop CPU, near-paper quality.
- ``paper``: the paper's hyperparameters (Adam 1e-5, batch 6, 6000 epochs,
  peephole cells, one signal per batch, no teacher forcing); for a GPU.

The environment variable ``PGAE_LITE_PROFILE`` picks the default profile;
:func:`profile_name` is the only code that reads it. The recipes of Table 1's
rows (:data:`ROWS`) are trainings (:data:`TRAININGS`): what each changes in a
profile (:func:`training_profile`). This module imports no module that
imports it, so nothing imports in a circle.
"""
from __future__ import annotations

import os
from dataclasses import asdict, dataclass, field, replace

from pgae_lite.cae import CAEConfig
from pgae_lite.data.dataset import check_vision_scaling
from pgae_lite.util.errors import ArgumentError
from pgae_lite.world.words import SIGNALS
from pgae_lite.world.patterns import pattern_number
from pgae_lite.model.signals import SIGNAL_PROBS
from pgae_lite.data.simulated import DatasetConfig

PROFILE_ENV = "PGAE_LITE_PROFILE"
PROFILE_NAMES = ("smoke", "book", "paper")   # the keys of PROFILES
#: The signals that take a description, and so may read phrasings (TrainConfig.phrasing_signals).
PHRASING_SIGNALS = ("execute", "repeat both", "repeat language")
#: Training options added after models were cached: left out of a recipe's key while at these defaults,
#: so that adding one does not rename (and retrain) every model trained before.
ADDED_LATER = {"phrasing_signals": PHRASING_SIGNALS, "phrasing_prob": 0.75}
#: The same for model options.
MODEL_ADDED_LATER = {"tuned_top_layer": False}


#: What a checkpoint saved before a ModelConfig setting existed was trained with.
LEGACY_MODEL_SETTINGS = {"joint_feedback": "predicted", "time_stride": 1, "gmu_norm": False, "plan_keyframes": 0}


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
    # the LSTM steps per sample. Stride 2 -> 3 cut an epoch by a tenth (results/epoch_time.json), and every
    # Table 1 median stayed at or better than the paper's (results/table1-original.json); stride 4 lost joint
    # precision (A2, the recipe's history, compares them).
    time_stride: int = 3
    # "lstm" = PGAE's language encoder; "pretrained" = PGAE-BERT's frozen transformer (pretrained.py);
    # "pretrained-attention" = the same transformer with a trained attention pooling (attention_pooling.py).
    language_encoder: str = "lstm"
    pretrained_model: str | None = None   # Hugging Face name or folder; None = the default shipped model
    # Not in the paper (which keeps the transformer frozen): with "pretrained-attention", free text reads
    # the transformer's top layer trained (tuned_layer.py, lr x LR_SCALE); the 869 fixed inputs stay frozen.
    tuned_top_layer: bool = False
    # Deviation from paper: the GMU layer-normalises W_A f_act + b before its tanh (layers.GatedMultimodalUnit;
    # paper: no normalisation). Without it, on some seeds the unbounded cell states in f_act saturate A_h for
    # every sample early in training, and describe never learns: one sentence for every action. The
    # measurements are on the book's results page (A2, "The describe collapse").
    gmu_norm: bool = True
    # Deviation from paper: a plan head reads h and predicts this many keyframes of the motion in training
    # (plan.PlanHead; 0 = none, the paper's). It makes h carry which cube the words mean in this scene, which
    # the recorded frames otherwise tell the decoder: without it the closed loop mostly moves the other cube.
    plan_keyframes: int = 10

    def __post_init__(self):
        if isinstance(self.plan_keyframes, bool) or not isinstance(self.plan_keyframes, int) or self.plan_keyframes < 0:
            raise ValueError(f"plan_keyframes must be a whole number >= 0 (0 = no plan head, the paper's); "
                             f"got {self.plan_keyframes!r}")
        if not isinstance(self.tuned_top_layer, bool):
            raise ValueError(f"tuned_top_layer must be True or False; got {self.tuned_top_layer!r}")
        if self.tuned_top_layer and self.language_encoder != "pretrained-attention":
            raise ValueError(f"tuned_top_layer needs language_encoder='pretrained-attention' (the free-form "
                             f"variant's encoder); got language_encoder={self.language_encoder!r}")
        if not isinstance(self.time_stride, int) or self.time_stride < 1:
            raise ValueError(f"time_stride must be a whole number >= 1 (1 = every step, the paper's); "
                             f"got {self.time_stride!r}")

    @classmethod
    def from_checkpoint(cls, saved: dict) -> "ModelConfig":
        """The config saved in a checkpoint; a setting it lacks is older than the checkpoint, so it
        takes the value the model was trained with (the paper's), not today's default."""
        return cls(**{**LEGACY_MODEL_SETTINGS, **saved})

    @property
    def state_dim(self) -> int:
        return 2 * self.layers * self.units  # [c_0; h_0; c_1; h_1]


@dataclass
class TrainConfig:
    """How PGAE is trained. Defaults are the ``book`` recipe."""

    # Deviation from paper: 300 epochs of batch 16 (paper: 6000 of batch 6 at a 300x smaller learning
    # rate). Its history (what was tried, what each change did) is on the book's results page (A2).
    epochs: int = 300
    batch_size: int = 16
    # Deviation from paper: each batch holds samples of one length (train.batch_indices); less time per epoch.
    length_batches: bool = True
    # Deviation from paper: AdamW 3e-3 with warm-up and cosine decay (paper: Adam 1e-5, constant).
    lr: float = 3e-3
    schedule: str = "cosine"            # "cosine" (warm-up, then cosine to 0) or "constant"
    warmup: float = 0.03                # fraction of steps of linear warm-up
    clip: float | None = 1.0            # gradient-norm clipping (paper: none)
    # Deviation from paper: decoupled weight decay (AdamW; paper: Adam, none). Measured on our data
    # (3 seeds, experiments/explore_recipe.py): describe 78/89/74% -> 92/94/90%, execute nRMSE median
    # 0.479 -> 0.451%, repeat action 0.487 -> 0.461%. Smaller weights favour one rule shared by all
    # actions ("say the moved cube's colour") over a table of action-specific ones.
    weight_decay: float = 0.1
    # Deviation from paper: a signal per sample (authors: one per batch).
    signals_per_sample: bool = True
    # How often each signal is drawn, in the order of language.SIGNALS (describe, execute,
    # repeat action, repeat both, repeat language); authors: 3/9, 3/9, 1/9, 1/9, 1/9.
    signal_probs: tuple[float, ...] = SIGNAL_PROBS
    # Deviation from paper: the language decoder is teacher-forced in training
    # (authors: it feeds back its own softmax, in training and at test time).
    teacher_language: bool = True
    # Deviation from paper: Gaussian noise of this std on the action encoder's inputs (vision and
    # joints, in model units [-1, 1]) in training. Measured on the authors' data (seed 0, 800
    # epochs): describe 65-87% -> 93%, repeat action nRMSE 0.61-0.72% -> 0.33%. The book uses 0.1 on
    # the visual features and 0.05 on the joints; measured on our data (seeds 0-2, 1000 epochs), the
    # vision noise 0.05 -> 0.1 lowered the largest repeat action nRMSE from 0.453 to 0.399%.
    input_noise: float = 0.1
    joint_input_noise: float | None = 0.05   # std on the joints part only; None: input_noise
    opposite_prob: float = 0.0          # chance that a sample shows the opposite agent's view
    # Deviation from paper: the visual features are whitened before the min/max scaling ("whiten",
    # see data.Normaliser; authors: "global", one min and max over all 30 features). Measured on our
    # data (3 seeds, experiments/explore_recipe.py --sim): describe 91.7/94.4/90.3% -> 95.4/98.1/93.1%,
    # execute nRMSE median 0.451 -> 0.453%, repeat action 0.461 -> 0.462%.
    vision_scaling: str = "whiten"
    language_weight: float = 1.0        # α
    # Deviation from paper: β = 4 (paper: 1). A 0.5% joint error is a loss of about 1e-4, the words' ~0.1.
    action_weight: float = 4.0          # β
    # Deviation from paper: γ, the weight of the plan head's error (plan.py) inside the action loss (paper: no
    # plan head). Used when ModelConfig.plan_keyframes > 0.
    plan_weight: float = 4.0
    # Not in the paper: K > 0 = samples with a description read, with probability phrasing_prob, one
    # of K sentences saying it in other words (phrasing_bank.py; PGAE-BERT only). 0 = the dataset's
    # descriptions.
    phrasings: int = 0
    # Chosen on generated validation sentences (experiments/validation_readback.py), never on the test
    # paraphrases: 0.75 read back more of them than 0.5, with Table 1 unchanged.
    phrasing_prob: float = 0.75
    # "all": the phrasings use the whole lexicon; "held-out": less phrase_lexicon.held_out_words(), so
    # that a test sentence with one of those words says something never trained on.
    phrasing_words: str = "all"
    # Not in the paper: the signals whose samples read phrasings (of execute, repeat both, repeat language).
    phrasing_signals: tuple[str, ...] = PHRASING_SIGNALS
    seed: int = 0
    max_train_samples: int | None = None  # a subset of the training split (smoke tests)
    checkpoint_every: int = 25          # epochs between checkpoints

    def __post_init__(self):
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
        if self.phrasing_words not in ("all", "held-out"):
            raise ValueError(f"TrainConfig phrasing_words must be 'all' or 'held-out'; got {self.phrasing_words!r}")
        for name in ("epochs", "batch_size", "checkpoint_every", "max_train_samples"):
            value = getattr(self, name)
            if name == "max_train_samples" and value is None:
                continue
            if isinstance(value, bool) or not hasattr(value, "__index__") or value < 1:
                also = " or None (all)" if name == "max_train_samples" else ""
                raise ValueError(f"TrainConfig {name} must be a whole number >= "
                                 f"1{also}; got {value!r}")


@dataclass(frozen=True)
class ChapterSettings:
    """How much the chapters do in a profile (defaults: the ``book`` profile's); no result depends on it."""

    runs_per_action: int = 4            # chapter 01, section 6: simulator runs per action and agent
    test_episodes: int = 36             # chapter 07: test episodes executed open and closed loop (36: one per pattern)
    paraphrase_episodes: int = 12       # chapter 07: test episodes told a free-form paraphrase
    every: int = 4                      # chapters 07 and 08: animations draw every `every`-th step


# Deviation from paper: batch 16 x 1000 iterations (~4 minutes on one CPU core) in place of
# 200 x 10,000 (~6 hours there). At equal compute, smaller batches (more updates) did better.
BOOK_CAE = CAEConfig("book", batch_size=16, iterations=1000, frame_stride=10)
#: Two arrangements (0: red+blue, 7: cyan+yellow), every action at both speeds;
#: 10 of these 24 patterns are test patterns.
SMOKE_PATTERNS = tuple(sorted(pattern_number(s, a, i) for s in (0, 1) for a in (0, 7) for i in range(6)))


@dataclass
class Profile:
    """A named run: data, CAE, model, training and the chapters' settings (defaults: the ``book`` profile's)."""

    name: str
    model: ModelConfig = field(default_factory=ModelConfig)
    train: TrainConfig = field(default_factory=TrainConfig)
    data: DatasetConfig = DatasetConfig()        # frozen: one shared instance is safe
    cae: CAEConfig = BOOK_CAE
    chapters: ChapterSettings = ChapterSettings()

    def to_dict(self) -> dict:
        """The recipe of the PGAE model: saved in its checkpoints and hashed into its cache key.

        Data and CAE are not in it (their own cache keys name them), nor the chapters' settings:
        another key here would change the key of every model trained before.
        """
        model, train = asdict(self.model), asdict(self.train)
        for options, added in ((model, MODEL_ADDED_LATER), (train, ADDED_LATER)):
            for key, default in added.items():    # at its default: the key of the models trained before
                if options[key] == default:
                    del options[key]
        return {"name": self.name, "model": model, "train": train}


PROFILES: dict[str, Profile] = {
    "smoke": Profile("smoke", ModelConfig(units=32), TrainConfig(
        epochs=3, batch_size=32, lr=3e-3, max_train_samples=96, checkpoint_every=1),
        data=DatasetConfig(variations=1, patterns=SMOKE_PATTERNS),
        cae=CAEConfig("smoke", batch_size=8, iterations=20, frame_stride=25),
        chapters=ChapterSettings(runs_per_action=1, test_episodes=2, paraphrase_episodes=2,
                                 every=10)),
    "book": Profile("book", ModelConfig()),
    "paper": Profile("paper", ModelConfig(cell="peephole", joint_feedback="predicted", time_stride=1,
                                    gmu_norm=False, plan_keyframes=0), TrainConfig(
        epochs=6000, batch_size=6, length_batches=False, lr=1e-5, schedule="constant", warmup=0.0, clip=None,
        signals_per_sample=False, teacher_language=False, input_noise=0.0,
        joint_input_noise=None,
        weight_decay=0.0, vision_scaling="global", action_weight=1.0, plan_weight=0.0,
        checkpoint_every=100),
        cae=CAEConfig("paper"), chapters=ChapterSettings(runs_per_action=6)),
}


def profile_name(name: str | None = None) -> str:
    """``name``, else ``$PGAE_LITE_PROFILE``, else ``"book"``: the name of a built-in profile.

    The only code that reads the environment variable. An unknown name (or not a string)
    raises an :class:`~pgae_lite.util.errors.ArgumentError` (a ``ValueError``) that lists the
    profiles (and names the variable if it came from there).
    """
    where = ""
    if name is None or name == "":
        name = os.environ.get(PROFILE_ENV, "book")
        where = f" (from the environment variable {PROFILE_ENV})" if PROFILE_ENV in os.environ else ""
    if not isinstance(name, str) or name not in PROFILE_NAMES:
        raise ArgumentError(f"unknown profile {name!r}{where}; the profiles are: "
                            f"{', '.join(PROFILE_NAMES)}")
    return name


def get_profile(name: str | None = None, **train_overrides) -> Profile:
    """A copy of a built-in profile; ``name=None`` reads ``PGAE_LITE_PROFILE`` (default ``book``).

    Keyword arguments override fields of its :class:`TrainConfig`, e.g. ``seed=1``.
    """
    p = PROFILES[profile_name(name)]
    bad = set(train_overrides) - set(asdict(p.train))
    if bad:
        raise ArgumentError(f"unknown training option(s) {sorted(bad)}; the options "
                            f"are: {', '.join(asdict(p.train))}")
    return replace(p, model=replace(p.model), train=replace(p.train, **train_overrides))


# --------------------------------------------------------------------------- Table 1's trainings
@dataclass(frozen=True)
class Training:
    """What one training changes in the profile's recipe (model and training options by name)."""

    model: dict = field(default_factory=dict)
    train: dict = field(default_factory=dict)


#: training name -> what it changes in the profile (model and training options)
TRAININGS: dict[str, Training] = {
    "PGAE": Training(),
    "PGAE-BERT": Training(model={"language_encoder": "pretrained"}),
    # Not a Table 1 row: the recipe without the plan head (plan.py), to show what the head changes (chapter 07).
    "PGAE-no-plan": Training(model={"plan_keyframes": 0}),
    # Authors' code: the opposite agent's view with probability 1/2 (describe and the repeat signals).
    "PGAE-views": Training(train={"opposite_prob": 0.5}),
    # Not a Table 1 row (free-form language): PGAE-BERT reading the transformer's tokens through an
    # attention pooling (attention_pooling.py) in place of the mean, with the transformer's top layer tuned
    # for free text (tuned_layer.py; the fixed inputs keep the frozen one), trained on 60 phrasings of every
    # instruction under repeat language only: it says a sentence back in the dataset's words and executes
    # those (instructions.py, route "said back"), so execute reads the descriptions alone. Chosen on
    # validation sentences (experiments/validation_readback.py), seed 1: said-back closed loop 87.04%,
    # against 80.56% with phrasings under all three signals.
    "PGAE-BERT-phrasings": Training(model={"language_encoder": "pretrained-attention",
                                           "tuned_top_layer": True},
                                    train={"phrasings": 60, "phrasing_signals": ("repeat language",)}),
    # The same with some words never trained on (phrase_lexicon.held_out_words): free_language.py's "unseen" measure.
    "PGAE-BERT-phrasings-held-out": Training(model={"language_encoder": "pretrained-attention",
                                                    "tuned_top_layer": True},
                                             train={"phrasings": 60, "phrasing_signals": ("repeat language",),
                                                    "phrasing_words": "held-out"}),
}
#: row -> (training, evaluated on the opposite agent's actions?)
ROWS: dict[str, tuple[str, bool]] = {
    "PGAE": ("PGAE", False),
    "PGAE-BERT": ("PGAE-BERT", False),
    "PGAE-self": ("PGAE-views", False),
    "PGAE-opposite": ("PGAE-views", True),
}


def training_profile(base: Profile, training: str, pretrained_model: str | None = None) -> Profile:
    """``base`` with one training's changes (and the pretrained model's name, for PGAE-BERT)."""
    t = TRAININGS[training]
    model = replace(base.model, **t.model)
    if training == "PGAE-BERT" and pretrained_model:
        model = replace(model, pretrained_model=pretrained_model)
    return replace(base, model=model, train=replace(base.train, **t.train))

