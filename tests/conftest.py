"""Shared fixtures: a tiny synthetic dataset, when present the authors' data, and torch's threads.

The authors' data (public repository oo222bs/PGAE, the folder holding
``target/``) is looked for in ``$PGAE_ORIGINAL_DATA``, else in
``../shared/pgae-original-data`` beside the project; tests that need it are
skipped with a message when it is absent.
"""
from __future__ import annotations

import os
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import torch

from pgae_lite.data.normaliser import Normaliser
from pgae_lite.data.original import load_original
from pgae_lite.data.toy import toy_dataset

ORIGINAL_DATA_ENV = "PGAE_ORIGINAL_DATA"
CACHE_ENV = "PGAE_LITE_CACHE"

# Tiny models run no faster on two threads, and much slower when another job shares the cores.
torch.set_num_threads(1)
# The tests read this repository's results/ wherever pytest is started from (pgae_lite.runs.results).
os.environ.setdefault("PGAE_LITE_REPOSITORY", str(Path(__file__).resolve().parents[1]))
DEFAULT_ORIGINAL_DATA = Path(__file__).resolve().parents[1].parent / "shared" / "pgae-original-data"


def original_data_path() -> Path:
    return Path(os.environ.get(ORIGINAL_DATA_ENV) or DEFAULT_ORIGINAL_DATA)


@pytest.fixture(scope="session")
def toy():
    """One recording of each of the 144 patterns (108 train, 36 test): fast to make."""
    return toy_dataset(variations=1)


def shorten(data, every: int = 10):
    """A copy of a dataset with every ``every``-th time step (lengths 100/50 -> 10/5): fast training."""
    short = data.subset(np.arange(len(data)))
    for name in ("joints", "vision", "vision_opposite"):
        setattr(short, name, np.ascontiguousarray(getattr(short, name)[:, ::every]))
    short.lengths = -(-short.lengths // every)
    return short


@pytest.fixture(scope="session")
def toy_short(toy):
    """The toy dataset with 10x fewer time steps (10 or 5): for tests that train."""
    return shorten(toy)


@pytest.fixture(scope="session")
def toy_tensors(toy):
    """Normalised tensors of the whole toy dataset (statistics from its training split)."""
    return Normaliser.fit(toy.split("train")).tensors(toy)


@pytest.fixture(scope="session")
def original_data() -> Path:
    """Path of the authors' data folder; skips the test when it is not there."""
    path = original_data_path()
    if not (path / "target").is_dir():
        pytest.skip(f"the authors' PGAE data is not at {path}: get the folder holding target/ "
                    f"(and actions.txt) from the public GitHub repository oo222bs/PGAE and put it "
                    f"there or set ${ORIGINAL_DATA_ENV}")
    return path


@pytest.fixture(scope="session")
def original(original_data):
    """The authors' dataset, loaded once per session (a few seconds)."""
    return load_original(original_data)


@pytest.fixture(scope="session", autouse=True)
def _private_cache(tmp_path_factory):
    """Tests never read or write the user's cache: one empty cache folder per test session."""
    old = os.environ.get(CACHE_ENV)
    os.environ[CACHE_ENV] = str(tmp_path_factory.mktemp("cache"))
    yield
    if old is None:
        os.environ.pop(CACHE_ENV, None)
    else:
        os.environ[CACHE_ENV] = old


@pytest.fixture(scope="session")
def smoke_episodes(_private_cache):
    """The smoke profile's simulated dataset (24 episodes), recorded once per session."""
    from pgae_lite.config import get_profile
    from pgae_lite.sim.dataset import generate

    config = get_profile("smoke").data
    return config, generate(config, progress=False)


@pytest.fixture(autouse=True)
def _seed():
    """Every test starts from the same global torch seed."""
    torch.manual_seed(0)


@pytest.fixture
def set_threads():
    """``set_threads(n)`` sets torch's thread count for the test; the count before is restored after it."""
    before = torch.get_num_threads()
    yield torch.set_num_threads
    torch.set_num_threads(before)


@pytest.fixture
def interrupt_training():
    """``interrupt_training(dataset, profile, out_dir, epoch)``: ``train`` stopped by an exception raised
    from its callback at ``epoch``, as if the process were killed there (to test resuming)."""
    from pgae_lite.train.loop import train

    class Interrupt(Exception):
        pass

    def stop(epoch_to_stop: int):
        def callback(epoch, model, record):
            if epoch == epoch_to_stop:
                raise Interrupt
        return callback

    def run(dataset, profile, out_dir, epoch: int) -> None:
        with pytest.raises(Interrupt):
            train(dataset, profile, out_dir=out_dir, progress=False, device="cpu", callback=stop(epoch))
    return run


class HandStartedCluster:
    """A ``dask scheduler`` and ``dask worker`` processes started by hand, as on a lab's machines."""

    def __init__(self):
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            port = s.getsockname()[1]
        self.address = f"tcp://127.0.0.1:{port}"
        self.env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
        self.procs = [self._start(self.env, "dask_scheduler", "--host", "127.0.0.1", "--port", str(port),
                                  "--dashboard-address", ":0")]
        time.sleep(3)

    def _start(self, env: dict, command: str, *args: str) -> subprocess.Popen:
        return subprocess.Popen([sys.executable, "-m", f"distributed.cli.{command}", *args], env=env,
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)

    def add_worker(self, *options: str, **env: str) -> subprocess.Popen:
        """A worker of one thread; ``env``: its environment's differences (another machine's cache)."""
        worker = self._start({**self.env, **env}, "dask_worker", self.address, "--nthreads", "1",
                             "--no-dashboard", *options)
        self.procs.append(worker)
        return worker

    def wait_for(self, workers: int) -> None:
        from distributed import Client

        with Client(self.address) as client:
            client.wait_for_workers(workers, timeout=120)

    def close(self) -> None:
        for p in self.procs:
            p.kill()
        for p in self.procs:
            p.wait(timeout=30)


@pytest.fixture
def dask_cluster():
    """A scheduler started by hand (add its workers with ``add_worker``); everything killed after the test."""
    cluster = HandStartedCluster()
    yield cluster
    cluster.close()
