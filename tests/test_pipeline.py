"""pgae_lite.runs.pipeline.trained_pgae: the profile's recipe, caching by profile; unknown profiles."""
from __future__ import annotations

import pytest

import pgae_lite.runs.pipeline as pipeline
from pgae_lite.config import get_profile

UNKNOWN = "unknown profile 'garbage'; the profiles are: smoke, book, paper"


@pytest.mark.parametrize("call", [lambda p: pipeline.simulated_dataset(p, progress=False),
                                  lambda p: pipeline.trained_cae(p, progress=False),
                                  lambda p: pipeline.trained_pgae("PGAE", p, progress=False)],
                         ids=["simulated_dataset", "trained_cae", "trained_pgae"])
def test_an_unknown_profile_is_a_clear_error(call, monkeypatch):
    with pytest.raises(ValueError) as e:
        call("garbage")
    assert str(e.value) == UNKNOWN
    monkeypatch.setenv("PGAE_LITE_PROFILE", "garbage")
    with pytest.raises(ValueError, match="'garbage' \\(from the environment variable PGAE_LITE_PROFILE\\)"):
        call(None)


def test_chapters_train_the_profiles_recipe_unless_told_otherwise(toy_short, monkeypatch):
    # The toy dataset stands in for the simulated one (recording it is tested in test_simdata).
    monkeypatch.setattr(pipeline, "simulated_dataset", lambda *a, **k: toy_short)
    small = dict(max_train_samples=8, batch_size=4)
    chapter = pipeline.trained_pgae("PGAE", "smoke", progress=False, **small)
    recipe = get_profile("smoke").train.epochs
    assert chapter.profile.train.epochs == recipe and len(chapter.history) == recipe
    explicit = pipeline.trained_pgae("PGAE", "smoke", progress=False, epochs=1, **small)
    assert explicit.profile.train.epochs == 1 and len(explicit.history) == 1
    again = pipeline.trained_pgae("PGAE", "smoke", progress=False, **small)   # cached: the same model
    assert again.history == chapter.history


def test_several_models_train_side_by_side_and_then_load():
    """smoke profile: two trainings in two worker processes, then both load from the cache unchanged.

    (Seed 7, which no other test or chapter trains: the two models are not in the cache yet.)
    """
    import shutil

    import torch

    from pgae_lite.config import TRAININGS, training_profile
    from pgae_lite.runs.pipeline import is_trained, model_folder, trained_pgae, trained_pgaes
    from pgae_lite.runs.trainings import NO_PLAN

    for training in (TRAININGS["PGAE"], NO_PLAN):     # left by an earlier run of this test in the same cache
        shutil.rmtree(model_folder(training_profile(get_profile("smoke", seed=7), training), training.name),
                      ignore_errors=True)
        assert not is_trained(training, get_profile("smoke"), 7)
    models = trained_pgaes(["PGAE", NO_PLAN], "smoke", seed=7, device="cpu", progress=False, workers=2)
    assert set(models) == {"PGAE", "PGAE-no-plan"}
    assert models["PGAE"].model.plan_head is not None and models["PGAE-no-plan"].model.plan_head is None
    again = trained_pgae("PGAE", "smoke", 7, device="cpu", progress=False)      # from the cache
    for a, b in zip(again.model.state_dict().values(), models["PGAE"].model.state_dict().values()):
        assert torch.equal(a, b)
    with pytest.raises(ValueError, match="unknown training 'PGAE-nope'"):
        trained_pgaes(["PGAE", "PGAE-nope"], "smoke")


def test_a_model_another_process_is_training_is_waited_for(monkeypatch, capsys):
    """Two chapters side by side ask for one model: the second waits for the first's training, then loads it."""
    import shutil
    import subprocess
    import sys

    from pgae_lite.config import training_profile
    from pgae_lite.runs import pipeline

    folder = pipeline.model_folder(training_profile(get_profile("smoke", seed=7), "PGAE"), "PGAE")
    shutil.rmtree(folder, ignore_errors=True)        # not trained yet (a trained one loads without waiting)
    pipeline.simulated_dataset("smoke", "cpu", progress=False)     # recorded before the other run starts
    monkeypatch.setattr(pipeline, "BUSY_POLL_SECONDS", 0.1)
    holds = ("import sys, time; from pgae_lite.util.storage import folder_lock\n"
             "with folder_lock(sys.argv[1]):\n    print('held', flush=True); time.sleep(3)")
    other = subprocess.Popen([sys.executable, "-c", holds, str(folder)], stdout=subprocess.PIPE, text=True)
    assert other.stdout.readline().strip() == "held"        # the other process is "training" now
    trained = pipeline.trained_pgae("PGAE", "smoke", 7, device="cpu", progress=True)
    assert other.wait(10) == 0 and trained.model.plan_head is not None
    assert "another process is training this model; waiting" in capsys.readouterr().out


def test_a_model_trained_on_phrasings_is_not_reused_after_the_lexicon_changes(monkeypatch):
    from dataclasses import replace

    import pgae_lite.freeform.phrase_lexicon as phrase_lexicon
    from pgae_lite.config import training_profile
    from pgae_lite.runs.trainings import PHRASINGS
    from pgae_lite.util.storage import config_digest

    prof = training_profile(get_profile("smoke"), PHRASINGS)
    before = pipeline.model_folder(prof, "PGAE-BERT-phrasings")
    assert pipeline.model_folder(prof, "PGAE-BERT-phrasings") == before        # the same sentences, the same model
    shorter = replace(phrase_lexicon.LEXICON, carriers=phrase_lexicon.LEXICON.carriers[:-1])
    monkeypatch.setattr(phrase_lexicon, "LEXICON", shorter)                      # one carrier sentence less
    assert pipeline.model_folder(prof, "PGAE-BERT-phrasings") != before
    plain = training_profile(get_profile("smoke"), "PGAE")                       # no phrasings: named as before
    assert pipeline.model_folder(plain, "PGAE").name.endswith(f"-PGAE-{config_digest(plain.to_dict())}")
