"""The recipes: the ``book`` profile, the paper's (paper Sec. 4, "Training Details") and ``smoke``.

A profile is a whole run, composed of each part's own settings, each defined beside what it
configures: what to record (:class:`~pgae_lite.data.simulated.DatasetConfig`), the CAE
(:class:`~pgae_lite.cae.CAEConfig`), the model (:class:`~pgae_lite.model.config.ModelConfig`),
its training (:class:`~pgae_lite.train.config.TrainConfig`) and how much the chapters do
(:class:`ChapterSettings`). The defaults of those settings are the ``book`` recipe; the paper's
profile is the book's with one override per line, each beside the paper section it comes from.

A profile's name is resolved into a :class:`Profile` once, where a run starts (the command
line, a chapter, a benchmark): :func:`get_profile`. Below that, functions take ``Profile``
values. The environment variable ``PGAE_LITE_PROFILE`` picks the default profile;
:func:`profile_name` is the only code that reads it.

Table 1's rows (:data:`ROWS`) and the family's beside them (:data:`FAMILY_ROWS`) are trainings
(:data:`TRAININGS`): what each changes in a profile (:func:`training_profile`). Trainings that
are not rows are built where they are used (:mod:`pgae_lite.runs.trainings`).
"""
from __future__ import annotations

import os
from dataclasses import asdict, dataclass, field, replace

from pgae_lite.cae import CAEConfig
from pgae_lite.data.simulated import DatasetConfig
from pgae_lite.model.config import ModelConfig
from pgae_lite.train.config import RECIPE_VERSION, TrainConfig
from pgae_lite.util.errors import ArgumentError
from pgae_lite.world.patterns import pattern_number

PROFILE_ENV = "PGAE_LITE_PROFILE"
#: ModelConfig's options of PTAE's transformer, and TrainConfig's of limited supervision: a recipe's dict
#: (Profile.to_dict) leaves them out where they are unused, so the models cached and checkpointed before
#: they existed keep their digests and their resume (a missing option reads as its default).
TRANSFORMER_OPTIONS = ("bottleneck", "heads", "feedforward", "dropout", "frame_positions")
PROFILE_NAMES = ("smoke", "book", "paper")   # the keys of PROFILES


@dataclass(frozen=True)
class ChapterSettings:
    """How much the chapters do in a profile (defaults: the ``book`` profile's); no result depends on it."""

    runs_per_action: int = 4            # chapter 01, section 6: simulator runs per action and agent
    test_episodes: int = 36             # chapter 07: test episodes executed open and closed loop (36: one per pattern)
    paraphrase_episodes: int = 12       # chapter 07: test episodes told a free-form paraphrase
    every: int = 4                      # chapters 07 and 08: animations draw every `every`-th step


@dataclass
class Profile:
    """A named run: data, CAE, model, training and the chapters' settings (defaults: the ``book`` profile's)."""

    name: str
    model: ModelConfig = field(default_factory=ModelConfig)
    train: TrainConfig = field(default_factory=TrainConfig)
    data: DatasetConfig = DatasetConfig()        # frozen: one shared instance is safe
    # Deviation from paper: the CAE trains 1000 steps of batch 16 (about 4 minutes on one CPU core) in
    # place of 10,000 of batch 200 (hours): at equal compute, smaller batches did better (A2).
    cae: CAEConfig = CAEConfig("book", batch_size=16, iterations=1000, frame_stride=10)
    chapters: ChapterSettings = ChapterSettings()

    def to_dict(self) -> dict:
        """The recipe of the PGAE model: saved in its checkpoints and hashed into its cache key.

        Data and CAE are not in it (their own cache keys name them), nor the chapters' settings.
        ``recipe_version`` (:data:`~pgae_lite.train.config.RECIPE_VERSION`) says which meaning
        of these options a checkpoint was trained with.
        """
        model, train = asdict(self.model), asdict(self.train)
        if model["bottleneck"] == "gmu":        # the transformer's settings mean nothing to a GMU
            for key in TRANSFORMER_OPTIONS:
                model.pop(key)
        for key in ("paired_share", "labelled_share"):
            if train[key] is None:              # full supervision: the recipe as it was
                train.pop(key)
        return {"name": self.name, "recipe_version": RECIPE_VERSION, "model": model, "train": train}


# --------------------------------------------------------------------------- the recipes
#: The book's recipe: every setting's default (each departure from the paper is marked where it is set).
BOOK = Profile("book")

#: The paper's settings: the book recipe with each departure taken back.
PAPER = replace(
    BOOK, name="paper",
    model=replace(
        BOOK.model,
        cell="peephole",              # Sec. 3: LSTMs with peephole connections (authors' code)
        joint_feedback="predicted",   # Sec. 3, Action Autoencoder: the decoder reads its own last prediction
        time_stride=1,                # Sec. 3: one LSTM step per time step
        gmu_norm=False,               # Sec. 3, Bottleneck: the GMU without normalisation
        plan_keyframes=0,             # Sec. 3: no plan head
    ),
    train=replace(
        BOOK.train,
        epochs=6000,                  # Sec. 4, Training Details: 6,000 epochs
        batch_size=6,                 # Sec. 4: a batch of 6 samples
        length_batches=False,         # authors' code: batches of any lengths
        lr=1e-5,                      # Sec. 4: learning rate 10^-5
        schedule="constant",          # Sec. 4: Adam at a constant rate
        warmup=0.0,
        clip=None,                    # authors' code: no gradient clipping
        weight_decay=0.0,             # Sec. 4: Adam, no weight decay
        signals_per_sample=False,     # authors' code: one signal per batch
        teacher_language=False,       # authors' code: the language decoder feeds back its own softmax
        input_noise=0.0,              # authors' code: no input noise
        joint_input_noise=None,
        vision_scaling="global",      # authors' code: one min and max over all 30 visual features
        action_weight=1.0,            # Sec. 3, Loss Function: alpha = beta = 1
        plan_weight=0.0,              # no plan head
        checkpoint_every=100,
    ),
    cae=CAEConfig("paper"),           # Sec. 3, Visual Feature Extraction: the authors' CAE training
    chapters=ChapterSettings(runs_per_action=6),
)

#: Two arrangements (0: red+blue, 7: cyan+yellow), every action at both speeds;
#: 10 of these 24 patterns are test patterns.
SMOKE_PATTERNS = tuple(sorted(pattern_number(s, a, i) for s in (0, 1) for a in (0, 7) for i in range(6)))

#: Seconds, for tests and for checking that a chapter runs: a small model, a few epochs, a few episodes.
SMOKE = replace(
    BOOK, name="smoke",
    model=replace(BOOK.model, units=32),
    train=replace(BOOK.train, epochs=3, batch_size=32, max_train_samples=96, checkpoint_every=1),
    data=DatasetConfig(variations=1, patterns=SMOKE_PATTERNS),
    cae=CAEConfig("smoke", batch_size=8, iterations=20, frame_stride=25),
    chapters=ChapterSettings(runs_per_action=1, test_episodes=2, paraphrase_episodes=2, every=10),
)

PROFILES: dict[str, Profile] = {"smoke": SMOKE, "book": BOOK, "paper": PAPER}


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


def get_profile(name: Profile | str | None = None, **train_overrides) -> Profile:
    """A copy of a profile: a built-in one by name (``None`` reads ``PGAE_LITE_PROFILE``, default
    ``book``), or of a :class:`Profile` value given.

    Keyword arguments override fields of its :class:`~pgae_lite.train.config.TrainConfig`, e.g. ``seed=1``.
    """
    p = name if isinstance(name, Profile) else PROFILES[profile_name(name)]
    bad = set(train_overrides) - set(asdict(p.train))
    if bad:
        raise ArgumentError(f"unknown training option(s) {sorted(bad)}; the options "
                            f"are: {', '.join(asdict(p.train))}")
    return replace(p, model=replace(p.model), train=replace(p.train, **train_overrides))


# --------------------------------------------------------------------------- Table 1's trainings
@dataclass(frozen=True)
class Training:
    """One training: its name (its cache folder's) and what it changes in a profile's recipe."""

    name: str
    model: dict = field(default_factory=dict)
    train: dict = field(default_factory=dict)
    # the model's own authors' settings, over the ``paper`` profile (PGAE's paper's) only
    paper_model: dict = field(default_factory=dict)
    paper_train: dict = field(default_factory=dict)


#: The trainings of Table 1's rows and of the family's (PTAE), by name.
TRAININGS: dict[str, Training] = {t.name: t for t in (
    Training("PGAE"),
    Training("PGAE-BERT", model={"language_encoder": "pretrained"}),
    # Authors' code: the opposite agent's view with probability 1/2 (describe and the repeat signals).
    Training("PGAE-views", train={"opposite_prob": 0.5}),
    # PTAE (model/ptae.py): the crossmodal transformer in place of the GMU, 128 wide in the book. Its paper's
    # model: 256 wide, feed-forward 1024, dropout 0.25, frames without positions; its training: Adam 1e-5,
    # batch 6, 2,500 epochs. Deviation from paper: at a constant rate (theirs decays in steps).
    Training("PTAE", model={"bottleneck": "crossmodal-transformer", "hidden": 128},
             paper_model={"hidden": 256, "feedforward": 1024, "dropout": 0.25, "frame_positions": False},
             paper_train={"epochs": 2500}),
)}
#: row -> (training, evaluated on the opposite agent's actions?)
ROWS: dict[str, tuple[str, bool]] = {
    "PGAE": ("PGAE", False),
    "PGAE-BERT": ("PGAE-BERT", False),
    "PGAE-self": ("PGAE-views", False),
    "PGAE-opposite": ("PGAE-views", True),
}
#: The family's rows beside Table 1's (not in PGAE's Table 1; benchmarks/family.py's table): ``reproduce
#: --rows`` takes them by name, ``--rows all`` means Table 1's.
FAMILY_ROWS: dict[str, tuple[str, bool]] = {"PRAE": ("PRAE", False), "PVAE": ("PVAE", False),
                                             "PVAE-BERT": ("PVAE-BERT", False),
                                             "PVAE-BERT-tuned": ("PVAE-BERT-tuned", False), "PTAE": ("PTAE", False)}
#: The family's rows configured per direction: trained by pgae_lite.family.train, not as a Training.
CONFIGURED_ROWS = ("PRAE", "PVAE", "PVAE-BERT", "PVAE-BERT-tuned")
EVERY_ROW: dict[str, tuple[str, bool]] = {**ROWS, **FAMILY_ROWS}


def as_training(training: Training | str) -> Training:
    """A :class:`Training`: itself, or one of Table 1's by name (:data:`TRAININGS`)."""
    if isinstance(training, Training):
        return training
    if training not in TRAININGS:
        raise ArgumentError(f"unknown training {training!r}; the rows' trainings are: {', '.join(TRAININGS)}; "
                            f"the others are Training values (pgae_lite.runs.trainings)")
    return TRAININGS[training]


def training_profile(base: Profile, training: Training | str, pretrained_model: str | None = None) -> Profile:
    """``base`` with one training's changes (and the pretrained model's name, for a pretrained encoder)."""
    t = as_training(training)
    paper = base.name == "paper"                       # the model's own authors' settings over the paper profile
    model = replace(base.model, **{**t.model, **(t.paper_model if paper else {})})
    if pretrained_model and model.language_encoder != "lstm":
        model = replace(model, pretrained_model=pretrained_model)
    train = replace(base.train, **{**t.train, **(t.paper_train if paper else {})})
    return replace(base, model=model, train=train)
