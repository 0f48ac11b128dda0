"""The sweep runner (pgae_lite/runs/sweep.py): the same units give the same results, digit for digit,
on a local cluster of two workers, of one worker, and on a scheduler and two workers started as
separate processes; a failing unit names itself."""
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
def test_a_local_cluster_gives_the_numbers_of_one_process(in_process, workers, tmp_path):
    assert run_sweep(train_unit, UNITS, workers=workers, logs=tmp_path) == in_process
    assert len(list(tmp_path.glob("sweep-*.log"))) == len(UNITS)       # one log per unit


@pytest.mark.timeout(300)
def test_a_cluster_started_by_hand_gives_the_same_numbers(in_process, dask_cluster):
    for _ in range(2):
        dask_cluster.add_worker()
    dask_cluster.wait_for(2)
    assert run_sweep(train_unit, UNITS, scheduler=dask_cluster.address) == in_process


@pytest.mark.timeout(120)
def test_a_failing_unit_names_itself():
    with pytest.raises(RuntimeError, match=r"unit 1 \(1\) failed: ValueError: unit one fails"):
        run_sweep(fails, [(0,), (1,), (2,)], workers=1)


def resumable_unit(seed: int, folder: str) -> dict:
    """A training that checkpoints every epoch into ``folder`` (and resumes from it), slowed down
    so that a test can kill its worker in the middle."""
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
        time.sleep(1.0)

    trained = train(data, profile, out_dir=folder, progress=False, callback=epoch_done)
    cells, _ = evaluate(trained.model, data, trained.normaliser)
    return {s: c["nrmse"] for s, c in cells.items()}


@pytest.mark.timeout(300)
def test_a_killed_worker_loses_only_its_unsaved_epochs(tmp_path, dask_cluster):
    import signal
    import threading

    from pgae_lite.train.checkpoint import CHECKPOINT

    whole = resumable_unit(0, str(tmp_path / "uninterrupted"))
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
    (result,) = run_sweep(resumable_unit, [(0, str(folder))], scheduler=cluster.address)
    assert killed, "the worker was not killed during the unit"
    epochs = (folder / "epochs.txt").read_text().split()
    assert epochs.count("1") == 1 and epochs[-1] == "6", epochs      # resumed from its checkpoint, not restarted
    assert result == whole                          # and gave the numbers of an uninterrupted run
