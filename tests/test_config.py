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
    """It is hashed into the cache keys of trained models and saved in checkpoints: nothing else goes in."""
    for name in PROFILE_NAMES:
        assert set(get_profile(name).to_dict()) == {"name", "recipe_version", "model", "train"}


def test_get_profile_copies():
    p = get_profile("smoke", seed=3)
    assert p.train.seed == 3 and PROFILES["smoke"].train.seed == 0
    assert p.model is not PROFILES["smoke"].model and p.data == PROFILES["smoke"].data


def test_recipes_live_here():
    import pgae_lite.runs.reproduce
    from pgae_lite.config import CONFIGURED_ROWS, EVERY_ROW, TRAININGS, training_profile
    from pgae_lite.runs.trainings import NO_PLAN, PHRASINGS, SIDE_TRAININGS

    assert list(TRAININGS) == ["PGAE", "PGAE-BERT", "PGAE-views", "PTAE"]  # the rows' (Table 1's, PTAE), no other
    assert not set(SIDE_TRAININGS) & set(TRAININGS)
    assert training_profile(get_profile("book"), NO_PLAN).model.plan_keyframes == 0
    assert training_profile(get_profile("book"), PHRASINGS).train.phrasings == 60
    with pytest.raises(ValueError, match="unknown training 'PGAE-no-plan'; the rows' trainings are"):
        training_profile(get_profile("book"), "PGAE-no-plan")
    assert {training for training, _ in EVERY_ROW.values()} - set(CONFIGURED_ROWS) == set(TRAININGS)
    assert pgae_lite.runs.reproduce.EVERY_ROW is EVERY_ROW
    smoke = get_profile("smoke")
    bert = training_profile(smoke, "PGAE-BERT", pretrained_model="bert-base-uncased")
    assert bert.model.language_encoder == "pretrained" and bert.model.pretrained_model == "bert-base-uncased"
    assert (bert.data, bert.cae, bert.chapters) == (smoke.data, smoke.cae, smoke.chapters)   # only the recipe changes
    views = training_profile(smoke, "PGAE-views")
    assert views.train.opposite_prob == 0.5 and smoke.train.opposite_prob == 0.0


def test_gmu_norm_is_the_book_recipe_and_not_the_papers():
    from pgae_lite.config import ModelConfig, get_profile
    from pgae_lite.model.pgae import PGAE
    assert ModelConfig().gmu_norm and get_profile("book").model.gmu_norm
    assert not get_profile("paper").model.gmu_norm
    assert PGAE(ModelConfig(units=8)).gmu.normalise_action



def test_a_checkpoint_of_another_recipe_version_is_refused():
    """One recipe version replaces the guesses of what an older checkpoint was trained with."""
    from pgae_lite.train.config import RECIPE_VERSION, saved_model_config
    from pgae_lite.util.storage import CheckpointMismatchError

    recipe = get_profile("smoke").to_dict()
    assert saved_model_config(recipe, "x.pt") == get_profile("smoke").model
    old = {k: v for k, v in recipe.items() if k != "recipe_version"}          # saved before versions
    with pytest.raises(CheckpointMismatchError, match="x.pt was trained with recipe version before versions; "
                                                      f"this pgae_lite reads version {RECIPE_VERSION}"):
        saved_model_config(old, "x.pt")
    with pytest.raises(CheckpointMismatchError, match="recipe version 1;"):
        saved_model_config({**recipe, "recipe_version": 1}, "x.pt")


def test_a_recipe_leaves_out_the_options_it_does_not_use_so_cached_models_keep_their_keys():
    """PTAE's transformer and limited supervision came after models were cached: PGAE's recipe dict is as before."""
    from pgae_lite.config import TRANSFORMER_OPTIONS, training_profile
    from pgae_lite.train.config import saved_model_config

    pgae = get_profile("book").to_dict()
    assert not set(TRANSFORMER_OPTIONS) & set(pgae["model"])
    assert not {"paired_share", "labelled_share"} & set(pgae["train"])
    assert saved_model_config(pgae, "x") == get_profile("book").model           # a missing option: its default
    ptae = training_profile(get_profile("book", paired_share=0.2), "PTAE")
    saved = ptae.to_dict()
    assert saved["model"]["bottleneck"] == "crossmodal-transformer" and saved["train"]["paired_share"] == 0.2
    assert saved_model_config(saved, "x") == ptae.model
