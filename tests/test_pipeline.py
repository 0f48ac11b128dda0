"""pgae_lite.runs.pipeline (and its data, pgae_lite.runs.data): the profile's recipe, caching by recipe; a
profile is a value resolved once (a name is refused); a world with a new colour goes through the same pipeline."""
from __future__ import annotations

import pytest

import pgae_lite.runs.pipeline as pipeline
from pgae_lite.config import get_profile
from pgae_lite.runs import data as run_data
from pgae_lite.runs.rows import TRAININGS
from pgae_lite.util.errors import ArgumentError, ArgumentTypeError

SMOKE = get_profile("smoke")


@pytest.mark.parametrize("call", [lambda p: run_data.simulated_dataset(p, progress=False),
                                  lambda p: run_data.trained_cae(p, progress=False),
                                  lambda p: pipeline.trained_model(TRAININGS["PGAE"], p, progress=False),
                                  lambda p: pipeline.trained_models([TRAININGS["PGAE"]], p, progress=False)],
                         ids=["simulated_dataset", "trained_cae", "trained_model", "trained_models"])
def test_a_profile_name_is_refused_the_profile_is_resolved_once(call, monkeypatch):
    """Every step takes a Profile value: a name (known or not) or None is a clear error naming get_profile."""
    monkeypatch.setenv("PGAE_LITE_PROFILE", "smoke")
    for name in ("smoke", "garbage", None):
        with pytest.raises(ArgumentTypeError) as e:
            call(name)
        assert str(e.value) == ("profile must be a Profile, resolved once where the run starts: "
                                f"pgae_lite.config.get_profile(name); got {'NoneType None' if name is None else 'str'}"
                                f"{'' if name is None else ' ' + repr(name)}")
    with pytest.raises(ArgumentError) as e:                    # and resolving a name that is none is clear too
        get_profile("nonsense")
    assert str(e.value) == "unknown profile 'nonsense'; the profiles are: smoke, book, paper"


def test_a_training_name_is_refused_the_training_is_a_value():
    for call in (lambda: pipeline.trained_model("PGAE", SMOKE, progress=False),
                 lambda: pipeline.trained_models(["PGAE"], SMOKE, progress=False)):
        with pytest.raises(ArgumentTypeError, match="training must be a Training of pgae_lite.runs.rows "
                                                    r"\(e.g. TRAININGS\['PGAE'\]\); got str 'PGAE'"):
            call()


def test_chapters_train_the_profiles_recipe_unless_told_otherwise(toy_short, monkeypatch):
    # The toy dataset stands in for the simulated one (recording it is tested in test_simdata).
    monkeypatch.setattr(pipeline, "loaded", lambda *a, **k: toy_short)
    small = get_profile(SMOKE, max_train_samples=8, batch_size=4)
    chapter = pipeline.trained_model(TRAININGS["PGAE"], small, progress=False)
    recipe = SMOKE.train.epochs
    assert chapter.profile.train.epochs == recipe and len(chapter.history) == recipe
    explicit = pipeline.trained_model(TRAININGS["PGAE"], get_profile(small, epochs=1), progress=False)
    assert explicit.profile.train.epochs == 1 and len(explicit.history) == 1
    again = pipeline.trained_model(TRAININGS["PGAE"], small, progress=False)   # cached: the same model
    assert again.history == chapter.history
    other_seed = pipeline.trained_model(TRAININGS["PGAE"], small, seed=1, progress=False)
    assert other_seed.profile.train.seed == 1 and other_seed.history != chapter.history


def test_several_models_train_side_by_side_and_then_load(dask_cluster, monkeypatch):
    """smoke profile: two trainings on two workers of the tests' one cluster, then both load from the cache
    unchanged. (Seed 7, which no other test or chapter trains: the two models are not in the cache yet.)"""
    import shutil

    import torch

    from pgae_lite.runs.pipeline import is_trained, model_folder, trained_model, trained_models, unit_profile
    from pgae_lite.runs.sweep import SCHEDULER_ENV

    dataset = run_data.simulated_dataset(SMOKE, progress=False)
    trainings = [TRAININGS["PGAE"], TRAININGS["PGAE-no-plan"]]
    for training in trainings:     # left by an earlier run of this test in the same cache
        shutil.rmtree(model_folder(unit_profile(SMOKE, training, 7, dataset), training.name), ignore_errors=True)
        assert not is_trained(training, SMOKE, 7, dataset)
    monkeypatch.setenv(SCHEDULER_ENV, dask_cluster.address)     # the side-by-side trainings: a sweep on it
    models = trained_models(trainings, SMOKE, seed=7, device="cpu", progress=False, workers=2)
    assert set(models) == {"PGAE", "PGAE-no-plan"}
    assert all(is_trained(training, SMOKE, 7, dataset) for training in trainings)
    assert models["PGAE"].model.plan_head is not None and models["PGAE-no-plan"].model.plan_head is None
    again = trained_model(TRAININGS["PGAE"], SMOKE, 7, device="cpu", progress=False)      # from the cache
    for a, b in zip(again.model.state_dict().values(), models["PGAE"].model.state_dict().values()):
        assert torch.equal(a, b)


@pytest.mark.parametrize("cores, missing, expected", [(2, 3, 3), (2, 5, 4), (1, 2, 2), (4, 2, 2)])
def test_missing_models_train_all_at_once_up_to_two_per_core(cores, missing, expected, monkeypatch):
    """Three trainings on two cores train at once (they share the cores and end together, not two then
    one), never more than two per core; the decision is trained_models' own, before any training starts."""
    asked = {}

    class Started(Exception):
        pass

    def sweep(work, units, *, workers, **_):
        asked.update(workers=workers, units=len(units))
        raise Started

    monkeypatch.setattr(pipeline.os, "cpu_count", lambda: cores)
    monkeypatch.setattr(pipeline, "run_sweep", sweep)
    monkeypatch.setattr(pipeline, "is_trained", lambda *a: False)
    trainings = [TRAININGS[n] for n in ("PGAE", "PGAE-no-plan", "PRAE-8", "PVAE", "PTAE")[:missing]]
    with pytest.raises(Started):
        pipeline.trained_models(trainings, SMOKE, device="cpu", progress=False)
    assert asked == {"workers": expected, "units": missing}


def test_a_model_another_process_is_training_is_waited_for(monkeypatch, capsys):
    """Two chapters side by side ask for one model: the second waits for the first's training, then loads it."""
    import shutil
    import subprocess
    import sys

    dataset = run_data.simulated_dataset(SMOKE, "cpu", progress=False)     # recorded before the other run starts
    folder = pipeline.model_folder(pipeline.unit_profile(SMOKE, TRAININGS["PGAE"], 8, dataset), "PGAE")
    shutil.rmtree(folder, ignore_errors=True)        # not trained yet (a trained one loads without waiting)
    monkeypatch.setattr(pipeline, "BUSY_POLL_SECONDS", 0.1)
    holds = ("import sys, time; from pgae_lite.util.storage import folder_lock\n"
             "with folder_lock(sys.argv[1]):\n    print('held', flush=True); time.sleep(3)")
    other = subprocess.Popen([sys.executable, "-c", holds, str(folder)], stdout=subprocess.PIPE, text=True)
    assert other.stdout.readline().strip() == "held"        # the other process is "training" now
    trained = pipeline.trained_model(TRAININGS["PGAE"], SMOKE, 8, device="cpu", progress=True)
    assert other.wait(10) == 0 and trained.model.plan_head is not None
    assert "another process is training this model; waiting" in capsys.readouterr().out


def test_a_model_trained_on_phrasings_is_not_reused_after_the_lexicon_changes(monkeypatch):
    import functools
    from dataclasses import replace

    import pgae_lite.freeform.phrase_lexicon as phrase_lexicon
    import pgae_lite.freeform.phrasing_bank as phrasing_bank
    from pgae_lite.util.storage import config_digest

    prof = TRAININGS["PGAE-BERT-phrasings"].profile(SMOKE)
    before = pipeline.model_folder(prof, "PGAE-BERT-phrasings")
    assert pipeline.model_folder(prof, "PGAE-BERT-phrasings") == before        # the same sentences, the same model
    shorter = replace(phrase_lexicon.LEXICON, carriers=phrase_lexicon.LEXICON.carriers[:-1])
    monkeypatch.setattr(phrase_lexicon, "LEXICON", shorter)                      # one carrier sentence less
    # (the sentences' digest is computed once per process: a process that reads the edited lexicon starts afresh)
    memo = phrasing_bank._sentences_digest
    monkeypatch.setattr(phrasing_bank, "_sentences_digest", functools.lru_cache(memo.__wrapped__))
    assert pipeline.model_folder(prof, "PGAE-BERT-phrasings") != before
    plain = TRAININGS["PGAE"].profile(SMOKE)                                     # no phrasings: its recipe's digest
    assert pipeline.model_folder(plain, "PGAE").name.endswith(f"-PGAE-{config_digest(plain.to_dict())}")


def test_every_training_has_its_own_cache_folder():
    """The folder's name holds the recipe's digest: two trainings, two seeds, two recipe versions never share one."""
    from pgae_lite.util.storage import config_digest

    folders = {pipeline.model_folder(t.profile(SMOKE), name) for name, t in TRAININGS.items()}
    assert len(folders) == len(TRAININGS)
    prae = TRAININGS["PRAE"].profile(SMOKE)
    assert pipeline.model_folder(prae, "PRAE") != pipeline.model_folder(get_profile(prae, seed=1), "PRAE")
    older = {**prae.to_dict(), "recipe_version": prae.to_dict()["recipe_version"] - 1}
    assert config_digest(older) not in pipeline.model_folder(prae, "PRAE").name


# --------------------------------------------------------------------------- a world with a new colour
def test_a_world_with_a_new_colour_is_the_papers_data_and_its_own(monkeypatch):
    """with_world: the smoke profile's data in a world with orange is made of two recordings, the paper's (the
    same episodes, the same cache folder) and the world's new patterns; the CAE, the features and the models are
    the pipeline's own, cached apart from the paper's (nothing is recorded here)."""
    from pgae_lite.config import with_world
    from pgae_lite.sim.dataset import DatasetConfig
    from pgae_lite.world.colours import with_colour

    world = with_colour("orange", "amber", (0.98, 0.50, 0.05, 1.0))
    coloured = with_world(SMOKE, world)
    parts = coloured.data.parts()
    assert len(parts) == 2, parts
    paper, new = parts
    assert paper == SMOKE.data and paper.key() == SMOKE.data.key()                # the paper's key, unchanged
    assert isinstance(new, DatasetConfig) and new.world == world and new.key() != paper.key()
    assert new.patterns and set(new.pattern_list()) <= set(world.new_patterns)    # only the world's new patterns
    assert any(world.pattern(p).is_test for p in new.pattern_list())             # some held out, for the check
    assert new.variations == SMOKE.data.variations and new.base_seed == SMOKE.data.base_seed
    assert sorted(p for part in parts for p in part.pattern_list()) == coloured.data.pattern_list()
    assert run_data.cae_path(coloured.data, coloured.cae) != run_data.cae_path(SMOKE.data, SMOKE.cae)
    monkeypatch.setattr(pipeline, "loaded", lambda *a, **k: pytest.fail("nothing is loaded here"))
    prof = TRAININGS["PGAE"].profile(coloured)
    assert pipeline.model_folder(prof, "PGAE") != pipeline.model_folder(TRAININGS["PGAE"].profile(SMOKE), "PGAE")
