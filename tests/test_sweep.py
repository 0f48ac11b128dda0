"""The sweep runner (pgae_lite/runs/sweep.py): the same units give the same results, digit for digit,
on a local cluster of two workers, of one worker, and on a scheduler and two workers started as
separate processes; a failing unit names itself."""
from __future__ import annotations

import os
import socket
import subprocess
import sys
import time

import pytest

from pgae_lite.runs.sweep import run_sweep


def train_unit(seed: int) -> dict:
    """One tiny training of the smoke recipe on the toy data, its Table 1 cells (a sweep's unit)."""
    import torch

    from pgae_lite.config import get_profile
    from pgae_lite.data.toy import toy_dataset
    from pgae_lite.evaluate import evaluate
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


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class HandStartedCluster:
    """A ``dask scheduler`` and ``dask worker`` processes started by hand, as on a lab's machines."""

    def __init__(self):
        self.address = f"tcp://127.0.0.1:{free_port()}"
        self.env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
        port = self.address.rsplit(":", 1)[1]
        self.procs = [self._start("dask_scheduler", "--host", "127.0.0.1", "--port", port,
                                  "--dashboard-address", ":0")]
        time.sleep(3)

    def _start(self, command: str, *args: str) -> subprocess.Popen:
        return subprocess.Popen([sys.executable, "-m", f"distributed.cli.{command}", *args], env=self.env,
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)

    def add_worker(self, *options: str) -> subprocess.Popen:
        worker = self._start("dask_worker", self.address, "--nthreads", "1", "--no-dashboard", *options)
        self.procs.append(worker)
        return worker

    def close(self) -> None:
        for p in self.procs:
            p.kill()
        for p in self.procs:
            p.wait(timeout=30)


@pytest.mark.timeout(300)
@pytest.mark.parametrize("workers", [2, 1])
def test_a_local_cluster_gives_the_numbers_of_one_process(in_process, workers, tmp_path):
    assert run_sweep(train_unit, UNITS, workers=workers, logs=tmp_path) == in_process
    assert len(list(tmp_path.glob("sweep-*.log"))) == len(UNITS)       # one log per unit


@pytest.mark.timeout(300)
def test_a_cluster_started_by_hand_gives_the_same_numbers(in_process, tmp_path):
    cluster = HandStartedCluster()
    try:
        for _ in range(2):
            cluster.add_worker()
        time.sleep(5)
        assert run_sweep(train_unit, UNITS, scheduler=cluster.address) == in_process
    finally:
        cluster.close()


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
    from pgae_lite.evaluate import evaluate
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
def test_a_killed_worker_loses_only_its_unsaved_epochs(tmp_path):
    import signal
    import threading

    from pgae_lite.train.checkpoint import CHECKPOINT

    whole = resumable_unit(0, str(tmp_path / "uninterrupted"))
    folder = tmp_path / "killed"
    cluster = HandStartedCluster()
    killed = []

    def kill_the_worker_after_a_checkpoint(worker):
        while not (folder / CHECKPOINT).exists():
            time.sleep(0.2)
        worker.send_signal(signal.SIGKILL)                   # the worker dies in the middle of the unit
        worker.wait(timeout=30)                              # and is reaped (a nanny would do it)
        killed.append(True)
        cluster.add_worker("--no-nanny")
    try:
        worker = cluster.add_worker("--no-nanny")
        time.sleep(5)
        threading.Thread(target=kill_the_worker_after_a_checkpoint, args=(worker,), daemon=True).start()
        (result,) = run_sweep(resumable_unit, [(0, str(folder))], scheduler=cluster.address)
    finally:
        cluster.close()
    assert killed, "the worker was not killed during the unit"
    epochs = (folder / "epochs.txt").read_text().split()
    assert epochs.count("1") == 1 and epochs[-1] == "6", epochs      # resumed from its checkpoint, not restarted
    assert result == whole                          # and gave the numbers of an uninterrupted run
