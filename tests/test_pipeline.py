"""pgae_lite.pipeline.trained_pgae: the profile's recipe, caching by profile; unknown profiles."""
from __future__ import annotations

import pytest

import pgae_lite.pipeline as pipeline
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
