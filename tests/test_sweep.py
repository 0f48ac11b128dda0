"""The sweep runner (pgae_lite/runs/sweep.py): the same units give the same results, digit for digit,
on a local cluster of two workers, on one worker, and on two workers started by hand as separate
processes; a failing unit names itself; a killed worker loses only its unsaved epochs. Every test
runs on the session's one cluster (tests/conftest.py, SharedCluster: the sweep runner's own
LocalCluster, whose scheduler also takes the workers started by hand)."""
from __future__ import annotations

import os
import time

import pytest

from pgae_lite.runs.sweep import run_sweep


def train_unit(seed: int) -> dict:
    """One tiny training of the smoke recipe on the toy data, its Table 1 cells (a sweep's unit)."""
    import torch

    from pgae_lite.config import get_profile
    from pgae_lite.data.toy import toy_dataset
    from pgae_lite.evaluate.table1 import evaluate
    from pgae_lite.train.loop import train

    torch.set_num_threads(1)
    data = toy_dataset(variations=1, patterns=range(24))
    profile = get_profile("smoke", seed=seed, epochs=2)
    trained = train(data, profile, progress=False)
    cells, _ = evaluate(trained.model, data, trained.normaliser)
    return {s: c["nrmse"] for s, c in cells.items()}


def fails(x: int) -> int:
    if x == 1:
        raise ValueError("unit one fails")
    return x


UNITS = [(0,), (1,), (2,)]


@pytest.fixture(scope="module")
def in_process():
    return [train_unit(*u) for u in UNITS]


@pytest.mark.timeout(300)
@pytest.mark.parametrize("workers", [2, 1])
def test_a_local_cluster_gives_the_numbers_of_one_process(in_process, workers, dask_cluster, tmp_path):
    """On the LocalCluster's two workers, and on one of them (which then runs the units one after another)."""
    with dask_cluster.on_local(workers):
        result = run_sweep(train_unit, UNITS, scheduler=dask_cluster.address, logs=tmp_path, name=f"local{workers}")
    assert result == in_process
    assert len(list(tmp_path.glob(f"local{workers}-*.log"))) == len(UNITS)       # one log per unit


@pytest.mark.timeout(300)
def test_a_cluster_started_by_hand_gives_the_same_numbers(in_process, dask_cluster):
    dask_cluster.hand_workers(2)
    with dask_cluster.on("hand"):
        assert run_sweep(train_unit, UNITS, scheduler=dask_cluster.address, name="by-hand") == in_process


@pytest.mark.timeout(120)
def test_a_failing_unit_names_itself(dask_cluster):
    with pytest.raises(RuntimeError, match=r"failing: unit 1 \(1\) failed: ValueError: unit one fails"):
        run_sweep(fails, [(0,), (1,), (2,)], scheduler=dask_cluster.address, name="failing")


def slowly(x: int) -> int:
    time.sleep(1.0)
    return x


def slowly_negated(x: int) -> int:
    time.sleep(1.0)
    return -x


@pytest.mark.timeout(120)
def test_two_sweeps_on_one_cluster_at_once_each_get_their_own_results(dask_cluster):
    """Two sweeps (two users of a lab's cluster, two chapters) on one scheduler at the same time, under the same
    sweep name: each gets the results of its own units, and each its results at all (one process's two clients:
    a sweep that waited on the other's event loop never heard of its results once the other had closed)."""
    import threading

    results = {}

    def sweep(work):
        results[work.__name__] = run_sweep(work, [(1,), (2,)], scheduler=dask_cluster.address, progress=False)
    threads = [threading.Thread(target=sweep, args=(work,), daemon=True) for work in (slowly, slowly_negated)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(timeout=100)
    assert results == {"slowly": [1, 2], "slowly_negated": [-1, -2]}


@pytest.mark.timeout(120)
def test_a_sweep_hears_its_results_when_another_client_of_its_process_closes(dask_cluster):
    """A sweep's client, then another (this process's latest, Dask's default) closed while the sweep runs: the
    sweep waits on its own client's event loop, not on the default's, and gets its results (it hung before)."""
    import threading

    from distributed import Client

    for _ in range(3):
        results = []
        mine, other = Client(dask_cluster.address), Client(dask_cluster.address)
        thread = threading.Thread(target=lambda: results.append(
            run_sweep(slowly, [(1,), (2,), (3,)], client=mine, progress=False)), daemon=True)   # noqa: B023
        thread.start()
        time.sleep(0.3)
        other.close()
        thread.join(timeout=30)
        mine.close()
        assert results == [[1, 2, 3]], "the sweep never heard of its results"


def resumable_unit(seed: int, folder: str, pause: float = 1.0) -> dict:
    """A training that checkpoints every epoch into ``folder`` (and resumes from it), slowed down by ``pause``
    seconds an epoch so that a test can kill its worker in the middle."""
    import torch

    from pgae_lite.config import get_profile
    from pgae_lite.data.toy import toy_dataset
    from pgae_lite.evaluate.table1 import evaluate
    from pgae_lite.train.loop import train

    torch.set_num_threads(1)
    data = toy_dataset(variations=1, patterns=range(24))
    profile = get_profile("smoke", seed=seed, epochs=6)
    def epoch_done(epoch, *_):                       # which epochs this unit trained, across attempts
        with open(os.path.join(folder, "epochs.txt"), "a") as f:
            f.write(f"{epoch}\n")
        time.sleep(pause)

    trained = train(data, profile, out_dir=folder, progress=False, callback=epoch_done)
    cells, _ = evaluate(trained.model, data, trained.normaliser)
    return {s: c["nrmse"] for s, c in cells.items()}


@pytest.mark.timeout(300)
def test_a_killed_worker_loses_only_its_unsaved_epochs(tmp_path, dask_cluster):
    """Its own workers (started by hand, without a nanny, one killed), on the session's scheduler."""
    import signal
    import threading

    from pgae_lite.train.checkpoint import CHECKPOINT

    whole = resumable_unit(0, str(tmp_path / "uninterrupted"), pause=0.0)
    folder = tmp_path / "killed"
    cluster = dask_cluster
    killed = []

    def kill_the_worker_after_a_checkpoint(worker):
        while not (folder / CHECKPOINT).exists():
            time.sleep(0.2)
        worker.send_signal(signal.SIGKILL)                   # the worker dies in the middle of the unit
        worker.wait(timeout=30)                              # and is reaped (a nanny would do it)
        killed.append(True)
        cluster.add_worker("--no-nanny")
    worker = cluster.add_worker("--no-nanny")
    cluster.wait_for(1)
    threading.Thread(target=kill_the_worker_after_a_checkpoint, args=(worker,), daemon=True).start()
    with cluster.on("own"):                                  # the unit runs on this test's workers only
        (result,) = run_sweep(resumable_unit, [(0, str(folder))], scheduler=cluster.address, name="killed")
    assert killed, "the worker was not killed during the unit"
    epochs = (folder / "epochs.txt").read_text().split()
    assert epochs.count("1") == 1 and epochs[-1] == "6", epochs      # resumed from its checkpoint, not restarted
    assert result == whole                          # and gave the numbers of an uninterrupted run
