"""Shared fixtures: a tiny synthetic dataset, when present the authors' data, torch's threads, and the one
Dask cluster every sweep of the tests runs on.

The authors' data (public repository oo222bs/PGAE, the folder holding
``target/``) is looked for in ``$PGAE_ORIGINAL_DATA``, else in
``../shared/pgae-original-data`` beside the project; tests that need it are
skipped with a message when it is absent.

The Dask cluster (:class:`SharedCluster`, fixture ``dask_cluster``) is started once per test session, at
its first use, so the sweep tests do not each pay for a scheduler and warm workers of their own.
"""
from __future__ import annotations

import os
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
    """``interrupt_training(dataset, profile, out_dir, epoch, **options)``: ``train`` stopped by an exception
    raised from its callback at ``epoch``, as if the process were killed there (to test resuming); ``options``:
    ``train``'s others (e.g. ``language``)."""
    from pgae_lite.train.loop import train

    class Interrupt(Exception):
        pass

    def stop(epoch_to_stop: int):
        def callback(epoch, model, record):
            if epoch == epoch_to_stop:
                raise Interrupt
        return callback

    def run(dataset, profile, out_dir, epoch: int, **options) -> None:
        with pytest.raises(Interrupt):
            train(dataset, profile, out_dir=out_dir, progress=False, device="cpu", callback=stop(epoch), **options)
    return run


class SharedCluster:
    """The test session's one Dask cluster, started once: the sweep runner's own LocalCluster of two
    single-threaded worker processes (:func:`pgae_lite.runs.sweep.client_for`), whose scheduler also takes
    workers started by hand (``dask worker ADDRESS``, as on a lab's machines). Every sweep of the tests runs
    on it (``run_sweep(..., scheduler=cluster.address)``); which workers take its units is chosen with
    :meth:`on_local` or :meth:`on` (a Dask annotation around the sweep)."""

    def __init__(self):
        from pgae_lite.runs.sweep import client_for

        self.client = client_for(workers=2)
        self.cluster = self.client.cluster
        self.address = self.cluster.scheduler_address
        self.local = sorted(self.client.scheduler_info()["workers"])     # the LocalCluster's two workers
        self.env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
        self.hand: list[subprocess.Popen] = []     # two workers started by hand, kept for the session ("hand")
        self.own: list[subprocess.Popen] = []      # a test's own workers, gone after it ("own")

    def _start(self, env: dict, *options: str) -> subprocess.Popen:
        return subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_worker", self.address,
                                 "--nthreads", "1", "--no-dashboard", *options], env=env,
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)

    def add_worker(self, *options: str, **env: str) -> subprocess.Popen:
        """A worker of one thread started by hand for this test alone (resource ``own``, units sent with
        ``on("own")``; killed after the test); ``env``: its environment's differences (another machine's cache)."""
        worker = self._start({**self.env, **env}, "--resources", "own=1", *options)
        self.own.append(worker)
        return worker

    def hand_workers(self, count: int = 2) -> None:
        """``count`` workers started by hand (resource ``hand``), started once and kept for the session."""
        while len(self.hand) < count:
            self.hand.append(self._start(self.env, "--resources", "hand=1"))
        self.wait_for(count, "hand")

    def workers_with(self, resource: str) -> list[str]:
        info = self.client.scheduler_info()["workers"]
        return [a for a, w in info.items() if w.get("resources", {}).get(resource)]

    def wait_for(self, workers: int, resource: str = "own") -> None:
        """Until ``workers`` workers with ``resource`` are connected to the scheduler."""
        deadline = time.monotonic() + 120
        while len(self.workers_with(resource)) < workers:
            assert time.monotonic() < deadline, f"{workers} worker(s) with {resource!r} did not start in 120 s"
            time.sleep(0.2)

    def on_local(self, count: int = 2):
        """Units of a sweep in this context run on the first ``count`` workers of the LocalCluster only."""
        import dask

        return dask.annotate(workers=self.local[:count])

    def on(self, resource: str):
        """Units of a sweep in this context run only on workers with ``resource`` (``hand``, ``own``)."""
        import dask

        return dask.annotate(resources={resource: 1})

    def end_test(self) -> None:
        """Kill this test's own workers and wait until the scheduler has let them go."""
        _stop(self.own)
        self.own = []
        deadline = time.monotonic() + 30
        while self.workers_with("own") and time.monotonic() < deadline:
            time.sleep(0.1)

    def close(self) -> None:
        _stop(self.own + self.hand)
        self.client.close()
        self.cluster.close()


def _stop(processes: list[subprocess.Popen]) -> None:
    for p in processes:
        p.kill()
    for p in processes:
        p.wait(timeout=30)


@pytest.fixture(scope="session")
def _shared_cluster(_private_cache):
    """The session's one Dask cluster (started at its first use; its workers read the session's cache)."""
    cluster = SharedCluster()
    yield cluster
    cluster.close()


@pytest.fixture
def dask_cluster(_shared_cluster):
    """The session's one Dask cluster; the workers a test adds with ``add_worker`` are killed after it."""
    yield _shared_cluster
    _shared_cluster.end_test()
