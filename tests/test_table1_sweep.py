"""``reproduce`` over seeds as a sweep (pgae_lite/runs/table1_unit.py through pgae_lite/runs/sweep.py).

The same smoke sweep writes the same result files, digit for digit, in this process, on a local
cluster of two workers and on two workers started by hand; a worker whose cache holds other
features (another machine's CAE) fails the sweep with a DataMismatchError, and one whose cache is
empty makes the data itself and gives the same numbers; a sweep on the cluster and a run in one
process writing one folder at once both finish, and leave the folder as one run would. Every
sweep runs on the session's one cluster (tests/conftest.py, SharedCluster).
"""
from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from pgae_lite.runs.reproduce import reproduce

SMOKE = dict(profile="smoke", rows="PGAE,PGAE-opposite", seeds=2, progress=False, device="cpu")


def written(out) -> tuple[dict, dict]:
    """A reproduce folder's cells (every row and seed) and every predictions file's arrays."""
    rows = json.loads((out / "results.json").read_text())["rows"]
    arrays = {str(p.relative_to(out)): dict(np.load(p)) for p in sorted(out.rglob("predictions*.npz"))}
    return rows, arrays


def assert_same(a, b) -> None:
    assert a[0] == b[0]                                        # every cell, mean and std
    assert a[1].keys() == b[1].keys()
    for name, arrays in a[1].items():
        for key, value in arrays.items():
            assert np.array_equal(value, b[1][name][key], equal_nan=value.dtype.kind == "f"), (name, key)


@pytest.fixture(scope="module")
def one_process(original_data, tmp_path_factory):
    out = tmp_path_factory.mktemp("one-process")
    reproduce(original_data, out_dir=out, workers=1, **SMOKE)
    assert not (out / "logs").exists()                         # one worker: no sweep, this process
    return written(out)


@pytest.mark.timeout(300)
def test_a_local_cluster_writes_the_files_of_one_process(original_data, one_process, tmp_path, dask_cluster):
    with dask_cluster.on_local():
        reproduce(original_data, out_dir=tmp_path, scheduler=dask_cluster.address, **SMOKE)
    assert len(list((tmp_path / "logs").glob("table1-*.log"))) == 4      # 2 trainings x 2 seeds
    assert_same(written(tmp_path), one_process)


@pytest.mark.timeout(300)
def test_workers_started_by_hand_write_the_files_of_one_process(original_data, one_process, tmp_path,
                                                               dask_cluster):
    dask_cluster.hand_workers(2)
    with dask_cluster.on("hand"):
        reproduce(original_data, out_dir=tmp_path, scheduler=dask_cluster.address, **SMOKE)
    assert_same(written(tmp_path), one_process)


def other_machines_cache(folder, profile: str, change) -> None:
    """A copy of this cache in ``folder`` whose features are ``change(features)``: what another
    machine's CAE (another version, another thread count) would have made of the same episodes."""
    import shutil

    from pgae_lite.config import get_profile
    from pgae_lite.data.dataset import PGAEDataset
    from pgae_lite.runs.data import cache_stem
    from pgae_lite.util.storage import cache_dir, config_digest

    prof = get_profile(profile)
    shutil.copytree(cache_dir(), folder, dirs_exist_ok=True)
    path = folder / "features" / f"{cache_stem(prof.data, prof.cae)}.npz"
    fingerprint = config_digest({"data": prof.data.to_dict(), "cae": prof.cae.to_dict()})
    data = PGAEDataset.load(path, fingerprint=fingerprint)
    data.vision, data.vision_opposite = change(data.vision), change(data.vision_opposite)
    data.save(path, fingerprint=fingerprint)


@pytest.mark.timeout(300)
def test_a_worker_with_another_cae_fails_the_sweep_clearly(smoke_episodes, tmp_path, dask_cluster):
    from pgae_lite.config import get_profile
    from pgae_lite.runs.data import simulated_dataset
    from pgae_lite.train.checkpoint import DataMismatchError

    simulated_dataset(get_profile("smoke"), "cpu", progress=False)     # this machine's data, made here
    elsewhere = tmp_path / "elsewhere-cache"
    other_machines_cache(elsewhere, "smoke", lambda v: (v * 1.05).astype(v.dtype))
    dask_cluster.add_worker(PGAE_LITE_CACHE=str(elsewhere))
    dask_cluster.wait_for(1)
    with pytest.raises(DataMismatchError, match=rf"not trained on this data.*trained on .*{elsewhere.name}"), \
            dask_cluster.on("own"):                             # the unit runs on that worker
        reproduce(None, out_dir=tmp_path / "out", scheduler=dask_cluster.address,
                  **{**SMOKE, "rows": "PGAE", "seeds": 1})


@pytest.mark.timeout(600)
def test_a_worker_with_an_empty_cache_makes_the_data_itself(smoke_episodes, tmp_path, dask_cluster):
    here = reproduce(None, out_dir=tmp_path / "here", workers=1, **{**SMOKE, "rows": "PGAE", "seeds": 1})
    dask_cluster.add_worker(PGAE_LITE_CACHE=str(tmp_path / "empty-cache"))
    dask_cluster.wait_for(1)
    with dask_cluster.on("own"):                                # the unit runs on that worker
        there = reproduce(None, out_dir=tmp_path / "there", scheduler=dask_cluster.address,
                          **{**SMOKE, "rows": "PGAE", "seeds": 1})
    assert (tmp_path / "empty-cache" / "features").is_dir()     # recorded and encoded on the worker
    assert there["rows"] == here["rows"]                        # and the same numbers


@pytest.mark.timeout(600)
def test_a_sweep_and_a_run_writing_one_folder_at_once_both_finish(original_data, one_process, tmp_path,
                                                                  dask_cluster):
    """Two ``reproduce`` commands into one folder at once, one a sweep on the cluster, the other training in its
    own process: the trainings they share wait for each other, and the folder holds one run's files."""
    out = tmp_path / "shared"
    command = [sys.executable, "-m", "pgae_lite", "reproduce", "--original-data", str(original_data),
               "--profile", "smoke", "--rows", "PGAE,PGAE-opposite", "--seeds", "2", "--out", str(out),
               "--device", "cpu", "--no-progress"]
    runs = [subprocess.Popen(command + extra, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
            for extra in (["--scheduler", dask_cluster.address], ["--workers", "1"])]
    outputs = [run.communicate(timeout=500)[0] for run in runs]
    assert [run.returncode for run in runs] == [0, 0], outputs
    assert_same(written(out), one_process)                     # one run's files, none half-written
