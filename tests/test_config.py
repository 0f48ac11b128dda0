"""pgae_lite.config: the one home of the profiles, and the only reader of PGAE_LITE_PROFILE."""
from __future__ import annotations

import pytest

from pgae_lite.cae import CAEConfig
from pgae_lite.config import (
    PROFILE_ENV,
    PROFILE_NAMES,
    PROFILES,
    SMOKE_PATTERNS,
    ChapterSettings,
    Profile,
    get_profile,
    profile_name,
)
from pgae_lite.sim.dataset import DatasetConfig

UNKNOWN = "unknown profile 'garbage'; the profiles are: smoke, book, paper"


def test_profile_name(monkeypatch):
    monkeypatch.delenv(PROFILE_ENV, raising=False)
    assert profile_name() == "book"
    monkeypatch.setenv(PROFILE_ENV, "smoke")
    assert profile_name() == "smoke" and profile_name("paper") == "paper"
    assert tuple(PROFILES) == PROFILE_NAMES == ("smoke", "book", "paper")


def test_an_unknown_profile_is_a_clear_error(monkeypatch):
    monkeypatch.delenv(PROFILE_ENV, raising=False)
    for call in (profile_name, get_profile):
        with pytest.raises(ValueError) as e:
            call("garbage")
        assert str(e.value) == UNKNOWN
    monkeypatch.setenv(PROFILE_ENV, "garbage")               # from the environment: it says so
    for call in (profile_name, get_profile):
        with pytest.raises(ValueError) as e:
            call()
        assert str(e.value) == (f"unknown profile 'garbage' (from the environment variable {PROFILE_ENV}); "
                                "the profiles are: smoke, book, paper")


def test_a_profile_holds_the_whole_run():
    smoke, book, paper = (get_profile(n) for n in PROFILE_NAMES)
    assert smoke.data == DatasetConfig(variations=1, patterns=SMOKE_PATTERNS) and len(SMOKE_PATTERNS) == 24
    assert book.data == paper.data == DatasetConfig()
    assert smoke.cae == CAEConfig("smoke", batch_size=8, iterations=20, frame_stride=25)
    assert book.cae == CAEConfig("book", batch_size=16, iterations=1000, frame_stride=10)
    assert paper.cae == CAEConfig()
    assert smoke.chapters == ChapterSettings(runs_per_action=1, test_episodes=2,
                                             paraphrase_episodes=2, every=10)
    assert book.chapters == ChapterSettings(runs_per_action=4, test_episodes=36,
                                            paraphrase_episodes=12, every=4)
    assert paper.chapters == ChapterSettings(runs_per_action=6, test_episodes=36,
                                             paraphrase_episodes=12, every=4)
    default = Profile("book")                                 # the defaults are the book profile
    assert (default.model, default.train, default.data, default.cae, default.chapters) == (
        book.model, book.train, book.data, book.cae, book.chapters)


def test_to_dict_holds_only_the_models_recipe():
    """It is hashed into the cache keys of trained models and saved in checkpoints: nothing else goes in,
    not even the name (the values are the recipe)."""
    from pgae_lite.train.config import RECIPE_VERSION

    for name in PROFILE_NAMES:
        recipe = get_profile(name).to_dict()
        assert set(recipe) == {"recipe_version", "model", "train"} and recipe["recipe_version"] == RECIPE_VERSION


def test_get_profile_copies():
    p = get_profile("smoke", seed=3)
    assert p.train.seed == 3 and PROFILES["smoke"].train.seed == 0
    assert p.model is not PROFILES["smoke"].model and p.data == PROFILES["smoke"].data


def test_recipes_live_here():
    """Every training and row is a value of pgae_lite.runs.rows; reproduce reads the same registry."""
    import pgae_lite.runs.reproduce
    from pgae_lite.bert.config import PretrainedConfig
    from pgae_lite.freeform.phrasing_bank import PhrasingsConfig
    from pgae_lite.runs.rows import FAMILY_ROWS, ROWS, TABLE1_ROWS, TRAININGS, Row, training_named
    from pgae_lite.util.errors import ArgumentError

    assert list(TRAININGS) == ["PGAE", "PGAE-BERT", "PGAE-views", "PTAE", "PRAE", "PVAE", "PVAE-BERT",
                               "PVAE-BERT-tuned", "PRAE-8", "PGAE-no-plan", "PGAE-BERT-phrasings",
                               "PGAE-BERT-phrasings-held-out"]
    assert all(t.name == name for name, t in TRAININGS.items())
    assert list(TABLE1_ROWS) == ["PGAE", "PGAE-BERT", "PGAE-self", "PGAE-opposite"]
    assert list(FAMILY_ROWS) == ["PRAE", "PVAE", "PVAE-BERT", "PVAE-BERT-tuned", "PTAE"]
    assert ROWS == {**TABLE1_ROWS, **FAMILY_ROWS} and all(isinstance(r, Row) for r in ROWS.values())
    assert ROWS["PGAE-opposite"].training is ROWS["PGAE-self"].training is TRAININGS["PGAE-views"]
    assert ROWS["PGAE-opposite"].opposite and not ROWS["PGAE-self"].opposite
    assert ROWS["PGAE"].paper["describe"] == (93.05, 0.23) and ROWS["PVAE"].paper is None
    assert {r.training.name for r in ROWS.values()} < set(TRAININGS)       # and trainings that are no row
    assert pgae_lite.runs.reproduce.ROWS is ROWS and pgae_lite.runs.reproduce.TABLE1_ROWS is TABLE1_ROWS
    book, smoke = get_profile("book"), get_profile("smoke")
    assert TRAININGS["PGAE-no-plan"].profile(book).model.plan_keyframes == 0
    assert TRAININGS["PGAE-BERT-phrasings"].profile(book).train.phrasings == PhrasingsConfig(
        per_meaning=60, signals=("repeat language",))
    assert training_named("PGAE-no-plan") is TRAININGS["PGAE-no-plan"]
    with pytest.raises(ArgumentError, match="unknown training 'PGAE-nope'; the trainings are: PGAE, PGAE-BERT"):
        training_named("PGAE-nope")
    bert = TRAININGS["PGAE-BERT"].profile(smoke, pretrained_model="bert-base-uncased")
    assert bert.model.language == PretrainedConfig(model="bert-base-uncased")
    assert TRAININGS["PGAE"].profile(smoke, pretrained_model="bert-base-uncased").model.language is None
    assert (bert.data, bert.cae, bert.chapters) == (smoke.data, smoke.cae, smoke.chapters)   # only the recipe changes
    views = TRAININGS["PGAE-views"].profile(smoke)
    assert views.train.opposite_prob == 0.5 and smoke.train.opposite_prob == 0.0


def test_gmu_norm_is_the_book_recipe_and_not_the_papers():
    from pgae_lite.config import ModelConfig, get_profile
    from pgae_lite.model.pgae import PGAE
    assert ModelConfig().gmu_norm and get_profile("book").model.gmu_norm
    assert not get_profile("paper").model.gmu_norm
    assert PGAE(ModelConfig(units=8)).gmu.normalise_action



def test_a_checkpoint_of_another_recipe_version_is_refused():
    """One recipe version replaces the guesses of what an older checkpoint was trained with."""
    from pgae_lite.runs.pipeline import recipe_from_dict
    from pgae_lite.train.checkpoint import check_recipe_version
    from pgae_lite.train.config import RECIPE_VERSION
    from pgae_lite.util.storage import CheckpointMismatchError

    recipe = get_profile("smoke").to_dict()
    assert check_recipe_version(recipe, "x.pt") is recipe
    assert recipe_from_dict(recipe) == (get_profile("smoke").model, get_profile("smoke").train)
    old = {k: v for k, v in recipe.items() if k != "recipe_version"}          # saved before versions
    with pytest.raises(CheckpointMismatchError, match="x.pt was trained with recipe version before versions; "
                                                      f"this pgae_lite reads version {RECIPE_VERSION}"):
        check_recipe_version(old, "x.pt")
    for version in (1, RECIPE_VERSION - 1):                                    # the recipes before the parts
        with pytest.raises(CheckpointMismatchError, match=f"recipe version {version};"):
            check_recipe_version({**recipe, "recipe_version": version}, "x.pt")


def test_a_recipe_writes_every_option_and_its_parts_by_kind():
    """No option is left out of a recipe (RECIPE_VERSION says what they meant): the parts a recipe does not use
    are None, and a part is written as its kind and its fields."""
    from dataclasses import fields

    from pgae_lite.config import ModelConfig, TrainConfig
    from pgae_lite.runs.rows import TRAININGS
    from pgae_lite.train.supervision import SupervisionConfig

    pgae = get_profile("book").to_dict()
    assert set(pgae["model"]) == {f.name for f in fields(ModelConfig)}
    assert set(pgae["train"]) == {f.name for f in fields(TrainConfig)}
    assert pgae["model"]["language"] is pgae["model"]["crossmodal"] is pgae["model"]["binding"] is None
    assert pgae["train"]["supervision"] is pgae["train"]["phrasings"] is None
    ptae = TRAININGS["PTAE"].profile(get_profile("book", supervision=SupervisionConfig(0.2)))
    saved = ptae.to_dict()
    assert saved["model"]["crossmodal"] == {"kind": "crossmodal-transformer", "heads": 4, "feedforward": 512,
                                            "dropout": 0.0, "frame_positions": True}
    assert saved["train"]["supervision"] == {"kind": "supervision", "share": 0.2, "of": "updates"}
    assert saved != pgae and saved["model"]["hidden"] == 128


def test_a_recipe_dict_gives_back_every_trainings_recipe():
    """recipe_from_dict(profile.to_dict()) round-trips every training of the registry, every part included."""
    from pgae_lite.runs.pipeline import recipe_from_dict
    from pgae_lite.runs.rows import TRAININGS

    for base in (get_profile("smoke"), get_profile("book"), get_profile("paper")):
        for training in TRAININGS.values():
            prof = training.profile(base, samples=864)
            assert recipe_from_dict(prof.to_dict()) == (prof.model, prof.train), (base.name, training.name)


def test_a_recipe_dict_with_an_unknown_part_is_a_clear_error():
    from pgae_lite.runs.pipeline import PART_KINDS, recipe_from_dict
    from pgae_lite.runs.rows import TRAININGS

    recipe = TRAININGS["PTAE"].profile(get_profile("smoke")).to_dict()
    recipe["model"]["crossmodal"]["kind"] = "mamba"
    kinds = ", ".join(PART_KINDS)
    with pytest.raises(ValueError, match=f"the model's settings: unknown part crossmodal='mamba'; the parts are: "
                                         f"{kinds}"):
        recipe_from_dict(recipe)
    recipe = get_profile("smoke").to_dict()
    recipe["train"]["phrasings"] = {"per_meaning": 2}                          # a part without its kind
    with pytest.raises(ValueError, match="the training's settings: unknown part phrasings=None"):
        recipe_from_dict(recipe)


# --------------------------------------------------------------------------- recipes are values
def test_nothing_depends_on_a_profiles_name():
    """A copy of the paper's profile under another name is the same recipe: the same dict, the same trainings."""
    from dataclasses import replace

    from pgae_lite.config import PAPER
    from pgae_lite.runs.rows import TRAININGS

    long = replace(PAPER, name="paper-long")
    assert long.to_dict() == PAPER.to_dict()
    for name in ("PRAE", "PVAE", "PTAE", "PGAE"):
        assert TRAININGS[name].profile(long, samples=864) == replace(TRAININGS[name].profile(PAPER, samples=864),
                                                                    name="paper-long"), name
        assert TRAININGS[name].profile(long, samples=864).to_dict() == \
            TRAININGS[name].profile(PAPER, samples=864).to_dict()


def test_authors_recipes_switches_the_authors_settings():
    """authors_recipes, not the name "paper", gives PRAE, PVAE and PTAE their authors' settings."""
    from dataclasses import replace

    from pgae_lite.config import BOOK, PAPER
    from pgae_lite.model.ptae import CrossmodalConfig
    from pgae_lite.runs.rows import TRAININGS
    from pgae_lite.util.errors import ArgumentError

    prae = TRAININGS["PRAE"]
    ours = prae.profile(BOOK, samples=864)
    assert (ours.train.batch_size, ours.train.lr, ours.train.epochs) == (BOOK.train.batch_size, BOOK.train.lr,
                                                                         BOOK.train.epochs)
    authors = prae.profile(replace(BOOK, authors_recipes=True), samples=864)          # named "book"
    assert (authors.train.batch_size, authors.train.lr, authors.train.epochs) == (50, 1e-3, round(20_000 * 50 / 864))
    pvae = TRAININGS["PVAE"].profile(PAPER, samples=864)
    assert (pvae.train.batch_size, pvae.train.lr, pvae.train.epochs) == (100, 1e-4, round(15_000 * 100 / 864))
    assert (pvae.train.weight_decay, pvae.train.schedule, pvae.train.clip) == (0.0, "constant", None)  # Adam
    assert TRAININGS["PRAE"].profile(replace(PAPER, authors_recipes=False), samples=864).train == \
        replace(PAPER.train, length_batches=False)                                  # the profile's own recipe
    assert TRAININGS["PVAE"].profile(PAPER, samples=10**9).train.epochs == 1           # at least one epoch
    with pytest.raises(ArgumentError, match="PRAE's authors count iterations: give the number of training samples"):
        prae.profile(PAPER)
    assert prae.profile(BOOK) == ours                                              # not asked without them
    ptae = TRAININGS["PTAE"].profile(PAPER)
    assert ptae.model.hidden == 256 and ptae.train.epochs == 2500
    assert ptae.model.crossmodal == CrossmodalConfig(feedforward=1024, dropout=0.25, frame_positions=False)
    book_ptae = TRAININGS["PTAE"].profile(BOOK)
    assert book_ptae.model.hidden == 128 and book_ptae.model.crossmodal == CrossmodalConfig()
    assert TRAININGS["PGAE"].profile(PAPER).train.epochs == 6000                      # PGAE keeps its own


def test_with_world_changes_only_the_data_and_keeps_the_recipe():
    from pgae_lite.config import with_world
    from pgae_lite.world.colours import with_colour

    smoke = get_profile("smoke")
    world = with_colour("orange", "amber", (0.98, 0.50, 0.05, 1.0))
    coloured = with_world(smoke, world)
    assert coloured.data.the_world == world and coloured.data.key() != smoke.data.key()
    assert (coloured.model, coloured.train, coloured.cae, coloured.chapters, coloured.to_dict()) == (
        smoke.model, smoke.train, smoke.cae, smoke.chapters, smoke.to_dict())
    assert smoke.data.world is None                                             # the profile itself unchanged


# --------------------------------------------------------------------------- the parts check themselves
def test_parts_refuse_what_cannot_go_with_their_recipe():
    from pgae_lite.bert.config import PretrainedConfig
    from pgae_lite.config import ModelConfig, TrainConfig
    from pgae_lite.freeform.attention_pooling import AttentionConfig
    from pgae_lite.freeform.phrasing_bank import PhrasingsConfig
    from pgae_lite.model.prae import BindingConfig
    from pgae_lite.model.ptae import CrossmodalConfig
    from pgae_lite.train.supervision import SupervisionConfig

    with pytest.raises(ValueError, match="PRAE and PVAE have no plan head: their ModelConfig needs plan_keyframes=0; "
                                         "got 10"):
        ModelConfig(plan_keyframes=10, binding=BindingConfig())
    assert ModelConfig(plan_keyframes=0, binding=BindingConfig()).binding == BindingConfig()
    with pytest.raises(ValueError, match="hidden=50.*among 4 heads: hidden must be a multiple of heads"):
        ModelConfig(hidden=50, crossmodal=CrossmodalConfig())
    assert ModelConfig(hidden=48, crossmodal=CrossmodalConfig(heads=3)).crossmodal.heads == 3
    for language in (PretrainedConfig(), AttentionConfig()):
        with pytest.raises(ValueError, match="reads the words as tokens itself; a language encoder"):
            ModelConfig(hidden=128, crossmodal=CrossmodalConfig(), language=language)
    with pytest.raises(ValueError, match="one bottleneck"):
        ModelConfig(hidden=128, plan_keyframes=0, crossmodal=CrossmodalConfig(), binding=BindingConfig())
    with pytest.raises(ValueError, match="ModelConfig language must be None or the settings of its"):
        ModelConfig(language="pretrained")                                   # the old spelling
    with pytest.raises(ValueError, match="TrainConfig supervision must be None or the settings of its"):
        TrainConfig(supervision=0.2)
    for share in (0, 0.0, -0.5, 1.5, True, "half"):
        with pytest.raises(ValueError, match="SupervisionConfig share must be a number in \\(0, 1\\]"):
            SupervisionConfig(share)
    with pytest.raises(ValueError, match="SupervisionConfig of must be one of updates, samples"):
        SupervisionConfig(0.5, of="batches")
    with pytest.raises(ValueError, match="PhrasingsConfig signals must name one or more of execute, repeat both, "
                                         "repeat language; got \\('describe',\\)"):
        PhrasingsConfig(signals=("describe",))
    with pytest.raises(ValueError, match="PhrasingsConfig words must be one of all, held-out; got 'some'"):
        PhrasingsConfig(words="some")
    for prob in (0, 1.5, True):
        with pytest.raises(ValueError, match="PhrasingsConfig prob must be a number in \\(0, 1\\]"):
            PhrasingsConfig(prob=prob)
    assert PhrasingsConfig(signals=["repeat language"]).signals == ("repeat language",)   # a list: a tuple
    for bad in (dict(heads=0), dict(feedforward=1.5), dict(dropout=1.0), dict(frame_positions=1)):
        with pytest.raises(ValueError, match="CrossmodalConfig"):
            CrossmodalConfig(**bad)
    with pytest.raises(ValueError, match="BindingConfig variational must be True or False"):
        BindingConfig(variational="yes")
    with pytest.raises(ValueError, match="PretrainedConfig model must be a Hugging Face name or a folder"):
        PretrainedConfig(model="")


def test_a_part_in_another_parts_place_is_refused_where_it_is_made():
    """A part is checked where its recipe is made: one in the wrong slot is a clear ValueError there, not an
    AttributeError when a model is built or trained from it."""
    from pgae_lite.config import ModelConfig, TrainConfig
    from pgae_lite.freeform.phrasing_bank import PhrasingsConfig
    from pgae_lite.model.prae import BindingConfig
    from pgae_lite.train.supervision import SupervisionConfig

    with pytest.raises(ValueError, match="language"):
        ModelConfig(plan_keyframes=0, language=BindingConfig())
    with pytest.raises(ValueError, match="supervision"):
        TrainConfig(supervision=PhrasingsConfig())
    with pytest.raises(ValueError, match="phrasings"):
        TrainConfig(phrasings=SupervisionConfig(0.5))
