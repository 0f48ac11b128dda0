"""pgae_lite.sim.dataset and pgae_lite.runs.pipeline: the cache of simulated episodes, features, the dataset."""
from __future__ import annotations

import numpy as np
import pytest

from pgae_lite.config import SMOKE_PATTERNS
from pgae_lite.data.dataset import PGAEDataset
from pgae_lite.sim.dataset import (
    CorruptEpisodeError,
    DatasetConfig,
    episode_folder,
    generate,
    load_episode,
    load_episode_file,
)
from pgae_lite.world.patterns import Pattern


def test_smoke_dataset_is_recorded_with_the_papers_split(smoke_episodes):
    config, report = smoke_episodes
    assert report.episodes == len(SMOKE_PATTERNS) == 24
    assert 0 < report.first_try <= 1 and report.megabytes > 0
    assert sorted(p.name for p in report.folder.glob("*.npz")) == [f"{p:03d}-0.npz" for p in SMOKE_PATTERNS]
    tests = [p for p in SMOKE_PATTERNS if Pattern.from_number(p).is_test]
    assert 0 < len(tests) < len(SMOKE_PATTERNS)                       # both splits are present
    ep = load_episode(config, 74)                                      # a fast test pattern
    assert ep.joints.shape == (50, 5) and ep.images.shape == ep.images_opposite.shape == (50, 120, 160, 3)
    assert ep.images.dtype == np.uint8 and ep.valid and ep.attempts >= 1


def test_second_call_uses_the_cache(smoke_episodes):
    config, _ = smoke_episodes
    again = generate(config, progress=False)
    assert again.recorded == 0 and again.corrupt == 0


def test_interrupted_run_resumes_and_damaged_files_are_recorded_again(smoke_episodes):
    config, _ = smoke_episodes
    folder = episode_folder(config)
    missing, damaged = folder / "000-0.npz", folder / "001-0.npz"
    before = load_episode_file(damaged)
    missing.unlink()                                                    # as if the run had stopped there
    raw = bytearray(damaged.read_bytes())
    raw[len(raw) // 2] ^= 0xFF                                          # one flipped byte
    damaged.write_bytes(bytes(raw))
    with pytest.raises(CorruptEpisodeError):
        load_episode_file(damaged)
    with pytest.warns(UserWarning, match="001-0.npz"):
        report = generate(config, progress=False)
    assert report.recorded == 2 and report.corrupt == 1
    after = load_episode_file(damaged)                                  # recorded again: same seed, same bytes
    assert np.array_equal(after.images, before.images) and np.array_equal(after.joints, before.joints)
    assert missing.exists()


def test_a_whole_file_missing_from_the_manifest_is_checked_not_recorded(smoke_episodes):
    config, _ = smoke_episodes
    folder = episode_folder(config)
    import json
    manifest = json.loads((folder / "manifest.json").read_text())
    manifest.pop("002-0")
    (folder / "manifest.json").write_text(json.dumps(manifest))
    report = generate(config, progress=False)
    assert report.recorded == 0 and "002-0" in json.loads((folder / "manifest.json").read_text())


def test_config_key_changes_with_the_config():
    a, b = DatasetConfig(), DatasetConfig(variations=5)
    assert a.key() != b.key() and a.key() == DatasetConfig().key()
    with pytest.raises(ValueError, match="not in this dataset"):
        load_episode(DatasetConfig(variations=1, patterns=(0,)), 5)


def test_simulated_dataset_has_the_authors_layout(smoke_episodes):
    from pgae_lite.config import get_profile
    from pgae_lite.runs.data import simulated_dataset

    ds = simulated_dataset(get_profile("smoke"), progress=False)
    n = len(SMOKE_PATTERNS)
    assert isinstance(ds, PGAEDataset) and len(ds) == n
    assert ds.joints.shape == (n, 100, 5) and ds.vision.shape == ds.vision_opposite.shape == (n, 100, 30)
    assert np.isfinite(ds.vision).all() and set(ds.lengths.tolist()) == {50, 100}
    assert (ds.vision[~ds.mask] == 0).all() and (ds.joints[~ds.mask] == 0).all()   # padding
    assert ds.descriptions.shape == (n, 8, 3)
    assert ds.is_test.tolist() == [Pattern.from_number(p).is_test for p in ds.pattern]
    assert not np.allclose(ds.vision, ds.vision_opposite)
    again = simulated_dataset(get_profile("smoke"), progress=False)                 # from the features cache
    np.testing.assert_array_equal(again.vision, ds.vision)


def test_parallel_workers_record_the_same_bytes_as_one_process():
    from pgae_lite.sim.record import record_episode

    config = DatasetConfig(variations=2, patterns=(77,))            # two fast episodes
    report = generate(config, workers=2, progress=False)
    assert report.recorded == 2
    for v in range(2):
        stored, direct = load_episode(config, 77, v), record_episode(77, v, config.sim, config.base_seed)
        assert np.array_equal(stored.images, direct.images) and np.array_equal(stored.joints, direct.joints)
