"""The recipes: the ``book`` profile, the paper's (paper Sec. 4, "Training Details") and ``smoke``.

A profile is a whole run, composed of each part's own settings, each defined beside what it
configures: what to record (:class:`~pgae_lite.sim.dataset.DatasetConfig`), the CAE
(:class:`~pgae_lite.cae.CAEConfig`), the model (:class:`~pgae_lite.model.config.ModelConfig`),
its training (:class:`~pgae_lite.train.config.TrainConfig`) and how much the chapters do
(:class:`ChapterSettings`). The defaults of those settings are the ``book`` recipe; the paper's
profile is the book's with one override per line, each beside the paper section it comes from.

A profile's name is resolved into a :class:`Profile` once, where a run starts (the command
line, a chapter, a benchmark): :func:`get_profile`. Below that, functions take ``Profile``
values, and no behaviour depends on a profile's name. The environment variable
``PGAE_LITE_PROFILE`` picks the default profile; :func:`profile_name` is the only code that reads it.
The trainings of Table 1's rows and of the family's are values too, beside the code that runs
them (:mod:`pgae_lite.runs.rows`).
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field, fields, replace

from pgae_lite.cae import CAEConfig
from pgae_lite.model.config import ModelConfig
from pgae_lite.sim.dataset import DatasetConfig
from pgae_lite.train.config import RECIPE_VERSION, TrainConfig
from pgae_lite.util.errors import ArgumentError
from pgae_lite.world.patterns import pattern_number

PROFILE_ENV = "PGAE_LITE_PROFILE"
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
    """A named run: data, CAE, model, training and the chapters' settings (defaults: the ``book`` profile's).

    ``authors_recipes``: every model trains with its own authors' settings where its training names them
    (the ``paper`` profile: :class:`pgae_lite.runs.rows.Training`); else with this profile's."""

    name: str
    model: ModelConfig = field(default_factory=ModelConfig)
    train: TrainConfig = field(default_factory=TrainConfig)
    data: DatasetConfig = DatasetConfig()        # frozen: one shared instance is safe
    # Deviation from paper: the CAE trains 1000 steps of batch 16 (about 4 minutes on one CPU core) in
    # place of 10,000 of batch 200 (hours): at equal compute, smaller batches did better (A2).
    cae: CAEConfig = CAEConfig("book", batch_size=16, iterations=1000, frame_stride=10)
    chapters: ChapterSettings = ChapterSettings()
    authors_recipes: bool = False

    def to_dict(self) -> dict:
        """The recipe of the model: every setting of its model and its training, saved in its checkpoints
        and hashed into its cache key. Not the name (the values are the recipe), not the data and the CAE
        (their own cache keys name them), nor the chapters' settings. ``recipe_version``
        (:data:`~pgae_lite.train.config.RECIPE_VERSION`) says which meaning of these options it was trained with.
        """
        return {"recipe_version": RECIPE_VERSION, "model": self.model.to_dict(), "train": self.train.to_dict()}


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
    authors_recipes=True,             # PRAE, PVAE, PTAE: their own papers' settings (runs/rows.py)
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
    options = [f.name for f in fields(p.train)]
    bad = set(train_overrides) - set(options)
    if bad:
        raise ArgumentError(f"unknown training option(s) {sorted(bad)}; the options "
                            f"are: {', '.join(options)}")
    return replace(p, model=replace(p.model), train=replace(p.train, **train_overrides))


def with_world(profile: Profile, world) -> Profile:
    """``profile`` in a world beyond the paper's (:func:`pgae_lite.world.colours.with_colour`, appendix A3): its
    data records the world's patterns (the paper's recordings, then the world's own: those the profile records
    of the paper's, and every new one) and its model reads and writes the world's words. The one pipeline does
    the rest (:mod:`pgae_lite.runs.pipeline`)."""
    patterns = profile.data.patterns
    if patterns is not None:                   # a profile of some of the paper's patterns (smoke): all the new ones
        patterns = tuple(patterns) + tuple(p for p in world.new_patterns if p not in patterns)
    return replace(profile, data=replace(profile.data, world=world, patterns=patterns))
