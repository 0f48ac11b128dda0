"""Hostile input, round three (issue 62, items 1 and 7): sweeps on one shared Dask cluster are isolated, and
every way the Dask path fails is one sentence, said before any data is loaded.

- Two ``reproduce`` commands of different epochs at once on the session's one scheduler each write their own
  recipe's results, checkpoints and predictions (before, the second got the first's results).
- A malformed address (in ``--scheduler``/``scheduler=`` or in ``$PGAE_DASK_SCHEDULER``), a wrong scheme, an
  address nobody listens on, a server that is not Dask's, a scheduler without workers: one sentence, no data read.
- A scheduler lost in the middle of a sweep: one sentence naming what was saved and how to resume.
"""
from __future__ import annotations

import contextlib
import json
import os
import socket
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

from pgae_lite.runs import reproduce as reproduce_module
from pgae_lite.runs import scheduler as scheduler_module
from pgae_lite.runs.reproduce import reproduce
from pgae_lite.runs.scheduler import SCHEDULER_ENV, SchedulerError
from pgae_lite.runs.sweep import run_sweep
from pgae_lite.util.errors import ArgumentError

SMOKE = dict(profile="smoke", rows="PGAE", progress=False, device="cpu")


def env(**changes: str) -> dict:
    """This process's environment (the session's private cache) for a command started by a test."""
    return {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path), **changes}


@pytest.fixture
def no_data(monkeypatch):
    """``reproduce`` fails the test if it loads any data."""
    def loaded(*_, **__):
        raise AssertionError("reproduce loaded its data before refusing the scheduler")
    monkeypatch.setattr(reproduce_module, "loaded", loaded)


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@contextlib.contextmanager
def own_scheduler(workers: int = 0, nthreads: int = 1):
    """A ``dask scheduler`` of this test alone (to lose it or leave it without workers), with ``workers``
    workers started by hand; its address. Every process it started is killed after it."""
    port = free_port()
    address = f"tcp://127.0.0.1:{port}"
    processes = [subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1",
                                   "--port", str(port), "--dashboard-address", ":0"], env=env(),
                                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    processes += [subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_worker", address, "--nthreads",
                                    str(nthreads), "--no-dashboard", "--no-nanny"], env=env(),
                                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL) for _ in range(workers)]
    try:
        yield address, processes[0]
    finally:
        for p in processes:
            p.kill()
        for p in processes:
            p.wait(timeout=30)


# --------------------------------------------------------------------------- two sweeps on one cluster
@pytest.mark.timeout(600)
def test_two_reproduce_runs_of_different_epochs_on_one_scheduler_each_get_their_own(original_data, tmp_path,
                                                                                   dask_cluster):
    """The issue's case: two ``reproduce --scheduler ADDRESS --seeds 2`` of different epochs at once on one
    scheduler (the session's); each folder holds its own recipe's results, checkpoints and predictions."""
    from pgae_lite.train.checkpoint import CHECKPOINT, load_checkpoint

    epochs = {"short": 3, "long": 12}
    command = [sys.executable, "-m", "pgae_lite", "reproduce", "--original-data", str(original_data), "--profile",
               "smoke", "--rows", "PGAE", "--seeds", "2", "--device", "cpu", "--no-progress", "--scheduler",
               dask_cluster.address]
    runs = {}
    for name, n in epochs.items():
        runs[name] = subprocess.Popen(command + ["--epochs", str(n), "--out", str(tmp_path / name)], env=env(),
                                      stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    outputs = {name: run.communicate(timeout=500)[0] for name, run in runs.items()}
    assert {name: run.returncode for name, run in runs.items()} == {"short": 0, "long": 0}, outputs
    for name, n in epochs.items():
        out = tmp_path / name
        report = json.loads((out / "results.json").read_text())
        assert report["trainings"]["PGAE"]["profile"]["train"]["epochs"] == n
        for seed in (0, 1):
            checkpoint = load_checkpoint(out / f"PGAE-seed{seed}" / CHECKPOINT)      # trained here, to its epochs
            assert checkpoint["epoch"] == checkpoint["profile"]["train"]["epochs"] == n
    short, long = (np.load(tmp_path / name / "predictions.npz") for name in epochs)
    assert any(not np.array_equal(short[k], long[k]) for k in short.files if k.endswith("_joints"))


# --------------------------------------------------------------------------- addresses that are not one
MALFORMED = ["garbage", "tcp://", "host:notaport", "tcp://host:99999", "://host:8786", "tcp://host :8786"]


@pytest.mark.parametrize("address", MALFORMED)
def test_a_malformed_scheduler_address_is_one_sentence_before_any_data(address, no_data, tmp_path):
    with pytest.raises(ArgumentError, match=r"^scheduler '.*' (is not a Dask scheduler's address|holds a space|"
                                            r"has no scheme).*tcp://host:8786"):
        reproduce(None, out_dir=tmp_path, scheduler=address, **SMOKE)


@pytest.mark.parametrize("address", ["garbage", "tcp://", "host:notaport"])
def test_a_malformed_address_in_the_environment_variable_names_it(address, no_data, tmp_path, monkeypatch):
    monkeypatch.setenv(SCHEDULER_ENV, address)
    with pytest.raises(ArgumentError, match=rf"^the environment variable {SCHEDULER_ENV} '.*' is not a Dask "
                                            r"scheduler's address"):
        reproduce(None, out_dir=tmp_path, **SMOKE)


def test_an_empty_environment_variable_is_refused(no_data, tmp_path, monkeypatch):
    monkeypatch.setenv(SCHEDULER_ENV, " ")
    with pytest.raises(ArgumentError, match=rf"{SCHEDULER_ENV} is set but empty.*unset it to run here"):
        reproduce(None, out_dir=tmp_path, **SMOKE)


@pytest.mark.parametrize("address", ["http://localhost:8787", "https://host:8786/status", "ucx://host:8786"])
def test_a_scheme_dask_does_not_speak_names_the_schemes_it_does(address, no_data, tmp_path):
    with pytest.raises(ArgumentError, match=r"which Dask's scheduler does not speak.*the schemes are: .*tcp://, "
                                            r"tls://, ws://, wss://$"):
        reproduce(None, out_dir=tmp_path, scheduler=address, **SMOKE)


@pytest.mark.timeout(120)
def test_the_command_line_says_it_in_one_line(tmp_path):
    """``--scheduler garbage`` and the same in the environment variable: exit status 2, one line, no traceback."""
    command = [sys.executable, "-m", "pgae_lite", "reproduce", "--profile", "smoke", "--out", str(tmp_path)]
    for extra, extra_env, says in ((["--scheduler", "garbage"], {}, "--scheduler 'garbage' is not"),
                                   ([], {SCHEDULER_ENV: "http://host:8787"},
                                    f"{SCHEDULER_ENV} 'http://host:8787' has")):
        run = subprocess.run(command + extra, env=env(**extra_env), capture_output=True, text=True, timeout=100)
        assert run.returncode == 2 and says in run.stderr and "Traceback" not in run.stderr, run.stderr
        assert [line for line in run.stderr.splitlines() if "error" in line] == [run.stderr.splitlines()[-1]]
    assert not any(tmp_path.iterdir())                    # nothing written


# --------------------------------------------------------------------------- schedulers that do not serve
@pytest.mark.timeout(60)
def test_an_address_nobody_listens_on_fails_within_the_stated_time(no_data, tmp_path, monkeypatch):
    assert scheduler_module.CONNECT_SECONDS <= 10                 # the stated time, not Dask's 30 s
    monkeypatch.setattr(scheduler_module, "CONNECT_SECONDS", 1.0)
    address = f"tcp://127.0.0.1:{free_port()}"
    started = time.monotonic()
    with pytest.raises(SchedulerError, match=rf"^no Dask scheduler answered at {address} within 1 s; start "
                                             r"one there"):
        reproduce(None, out_dir=tmp_path, scheduler=address, **SMOKE)
    assert time.monotonic() - started < 8


@pytest.mark.timeout(60)
def test_a_server_that_is_not_a_dask_scheduler_is_named(no_data, tmp_path, monkeypatch):
    """A web server (the dashboard's port, say) answers, but not as a scheduler (Dask read 3 EiB from it)."""
    monkeypatch.setattr(scheduler_module, "CONNECT_SECONDS", 2.0)
    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen(4)

    def answer():
        with contextlib.suppress(OSError):
            while True:
                connection, _ = server.accept()
                connection.sendall(b"HTTP/1.1 400 Bad Request\r\n\r\n")
    threading.Thread(target=answer, daemon=True).start()
    try:
        with pytest.raises(SchedulerError, match=r"but not as a Dask scheduler .*not its dashboard's"):
            reproduce(None, out_dir=tmp_path, scheduler=f"tcp://127.0.0.1:{server.getsockname()[1]}", **SMOKE)
    finally:
        server.close()


@pytest.mark.timeout(120)
def test_a_scheduler_without_workers_says_so_within_the_stated_time(no_data, tmp_path, monkeypatch):
    monkeypatch.setattr(scheduler_module, "WORKERS_SECONDS", 1.0)
    with own_scheduler() as (address, _):
        monkeypatch.setenv(SCHEDULER_ENV, address)
        with pytest.raises(SchedulerError, match=rf"^no workers joined the Dask scheduler at {address} \(from the "
                                                 rf"environment variable {SCHEDULER_ENV}\) within 1 s; start one "
                                                 rf"\(dask worker {address} --nthreads 1\)"):
            reproduce(None, out_dir=tmp_path, **SMOKE)


# --------------------------------------------------------------------------- a scheduler lost mid-sweep
def quick_or_slow(seconds: float, marker: str) -> float:
    """A unit that leaves ``marker`` when it starts, then takes ``seconds``."""
    open(marker, "w").close()
    time.sleep(seconds)
    return seconds


@pytest.mark.timeout(120)
def test_a_scheduler_lost_mid_sweep_says_what_was_done(tmp_path):
    with own_scheduler(workers=1, nthreads=2) as (address, scheduler):
        def kill_after_the_quick_unit():
            while not ((tmp_path / "quick").exists() and (tmp_path / "slow").exists()):
                time.sleep(0.1)
            time.sleep(1.5)                         # the quick unit's result has reached the sweep
            scheduler.kill()
        threading.Thread(target=kill_after_the_quick_unit, daemon=True).start()
        started = time.monotonic()
        with pytest.raises(SchedulerError, match=rf"^the Dask scheduler at {address} was lost in the middle of the "
                                                 r"sweep 'lost', with 1 of 2 units done; resume here"):
            run_sweep(quick_or_slow, [(0.0, str(tmp_path / "quick")), (60.0, str(tmp_path / "slow"))],
                      scheduler=address, name="lost", progress=False, on_lost="resume here")
        assert time.monotonic() - started < 50                   # not the slow unit's minute


@pytest.mark.timeout(240)
def test_reproduce_with_its_scheduler_lost_names_its_checkpoints_and_how_to_resume(original_data, tmp_path):
    from pgae_lite.train.checkpoint import CHECKPOINT

    out = tmp_path / "out"
    checkpoint = out / "PGAE-seed0" / CHECKPOINT
    with own_scheduler(workers=1) as (address, scheduler):
        def kill_after_a_checkpoint():
            while not checkpoint.exists():
                time.sleep(0.1)
            scheduler.kill()
        threading.Thread(target=kill_after_a_checkpoint, daemon=True).start()
        with pytest.raises(SchedulerError, match=rf"^the Dask scheduler at {address} was lost in the middle of the "
                                                 rf"sweep 'table1', with 0 of 1 units done; each training finished "
                                                 rf"or checkpointed so far is saved in .*{out.name} \(PGAE-seed0: "
                                                 r"checkpoint.pt\); run the same command again"):
            reproduce(original_data, out_dir=out, scheduler=address, epochs=5000, **SMOKE)
    assert checkpoint.exists()
