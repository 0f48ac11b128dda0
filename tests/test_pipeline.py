"""pgae_lite.pipeline.trained_pgae: the chapters' epoch budget, caching by profile."""
from __future__ import annotations

import pgae_lite.pipeline as pipeline


def test_chapter_epochs_apply_unless_epochs_are_given(toy_short, monkeypatch):
    # The toy dataset stands in for the simulated one (recording it is tested in test_simdata).
    monkeypatch.setattr(pipeline, "simulated_dataset", lambda *a, **k: toy_short)
    monkeypatch.setitem(pipeline.CHAPTER_EPOCHS, "smoke", 2)
    small = dict(max_train_samples=8, batch_size=4)
    chapter = pipeline.trained_pgae("PGAE", "smoke", progress=False, **small)
    assert chapter.profile.train.epochs == 2 and len(chapter.history) == 2
    explicit = pipeline.trained_pgae("PGAE", "smoke", progress=False, epochs=1, **small)
    assert explicit.profile.train.epochs == 1 and len(explicit.history) == 1
    again = pipeline.trained_pgae("PGAE", "smoke", progress=False, **small)   # cached: the same model
    assert again.history == chapter.history
