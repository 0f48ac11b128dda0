"""Sweeps: many trainings as tasks on a Dask cluster, from one laptop to a lab's cluster.

A benchmark that trains several models (Table 1 over seeds, the ablations, the free-form
variants: the paper's Sec. 4 measured many times) is a list of *units*: one call
``work(*args)`` trains and measures one model, on one thread, in its own resumable folder
(one training = one config digest). :func:`run_sweep` submits every unit as a task to a Dask
cluster and returns the results in the units' order:

- by default a ``LocalCluster`` on this machine, one single-threaded worker process per core
  (``workers`` to choose how many);
- with ``scheduler="tcp://host:8786"`` (or ``$PGAE_DASK_SCHEDULER``) an existing cluster: started
  by hand (``dask scheduler``, then ``dask worker tcp://host:8786 --nthreads 1`` on each
  machine), over SSH (``distributed.SSHCluster``) or on SLURM/PBS (``dask-jobqueue``). Its address
  is checked, and the scheduler reached with a worker joined, before any unit is sent
  (:mod:`pgae_lite.runs.scheduler`: each failure one sentence).

Sweeps share a cluster without sharing results: every task's key holds a token drawn for its
sweep, so a task stands for "unit K of this sweep", whose arguments (recipe, data, seed,
training, output folder) are its sweep's own. Two sweeps, at once or one after the other, with
the same recipe or not, never receive each other's results; identical work is shared on purpose
on disk instead (a unit's training folder: a second run with the same recipe loads, or waits for,
the first run's model). A scheduler lost in the middle of a sweep is one sentence that says what
was saved and how to resume (``on_lost``).

A worker that dies in the middle of a unit loses that unit's unsaved epochs only: the scheduler
gives the task to another worker (up to ``allowed_failures`` times) and the unit resumes from
its checkpoint. One line of progress (units done, running, left, time left) is printed as units
finish, each unit's output goes to its own log file, and the dashboard's address is printed.
"""
from __future__ import annotations

import contextlib
import os
import sys
import time
import uuid
from concurrent.futures import CancelledError
from pathlib import Path

from pgae_lite.runs.scheduler import (
    SCHEDULER_ENV,
    SchedulerError,
    connect,
    disconnect,
    is_lost,
    lost,
    scheduler_address,
)


def _logged(work, log: str | None, *args):
    """``work(*args)`` with its output (stdout and stderr) in the file ``log``, if given."""
    if log is None:
        return work(*args)
    Path(log).parent.mkdir(parents=True, exist_ok=True)
    with open(log, "a", encoding="utf-8") as f, contextlib.redirect_stdout(f), contextlib.redirect_stderr(f):
        return work(*args)


def client_for(scheduler: str | None = None, workers: int | None = None):
    """A Dask client: on the cluster at ``scheduler`` (else ``$PGAE_DASK_SCHEDULER``), checked and with a worker
    joined (:func:`~pgae_lite.runs.scheduler.connect`), or on a new ``LocalCluster`` of ``workers``
    single-threaded processes (default: one per core)."""
    import dask
    from distributed import Client, LocalCluster

    named = scheduler_address(scheduler)
    if named is not None:
        return connect(named)
    n = workers or os.cpu_count() or 1
    if not isinstance(n, int) or n < 1:
        raise ValueError(f"workers must be a whole number >= 1; got {workers!r}")
    # Nothing set in this process's environment before each worker starts (Dask's default sets
    # MALLOC_TRIM_THRESHOLD_ and OMP_NUM_THREADS here, for every later child of this process too):
    # each worker sets its own (pgae_lite.runs.sweep_worker).
    with dask.config.set({"distributed.nanny.pre-spawn-environ": {}}):
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=":0")
    return Client(cluster)


def _label(unit: tuple) -> str:
    """A unit's arguments in a few words: a recipe or a training by its name, others as written (cut short)."""
    shown = [a.name if isinstance(getattr(a, "name", None), str) else repr(a) for a in unit]
    return "(" + ", ".join(s if len(s) <= 60 else s[:57] + "..." for s in shown) + ")"


def _progress(done: int, running: int, total: int, elapsed: float) -> str:
    """One line: units done, running and waiting, and the time left at the pace so far."""
    left = total - done
    eta = f", about {elapsed / done * left / 60:.1f} min left" if done and left else ""
    return f"sweep: {done}/{total} units done, {running} running, {left - running} waiting{eta}"


def run_sweep(work, units: list[tuple], *, workers: int | None = None, scheduler: str | None = None,
              logs: str | Path | None = None, name: str = "sweep", progress: bool = True, client=None,
              on_lost: str = "what each unit saved is kept: run the sweep again to resume from it") -> list:
    """``[work(*unit) for unit in units]``, each unit a task on a Dask cluster (see the module).

    ``work`` must be importable or picklable by the workers (a module-level function) and should
    set its own threads (one: these networks gain nothing from two). ``logs``: a folder for one
    log file per unit (``NAME-K.log``). A unit that raises makes the sweep raise, naming it and
    its error. ``progress``: print the dashboard's address and the progress line. ``client``: a
    client already connected (:func:`client_for`), which the caller closes; else one is made and
    closed here. A scheduler lost during the sweep raises a
    :class:`~pgae_lite.runs.scheduler.SchedulerError` that ends with ``on_lost`` (what was saved,
    how to resume).
    """
    from distributed import as_completed

    if not units:
        return []
    own = client is None
    client = client_for(scheduler, workers) if own else client
    address, done = client.scheduler.address, 0
    try:
        from pgae_lite.runs.sweep_worker import OneCoreWorker

        client.register_plugin(OneCoreWorker(), name="pgae-lite-one-core-worker")
        if progress and client.dashboard_link:
            print(f"{name}: Dask dashboard at {client.dashboard_link}", flush=True)
        width = max(1, len(client.scheduler_info().get("workers", {})))
        sweep = uuid.uuid4().hex[:12]        # this sweep's tasks: on a shared cluster, never another sweep's
        futures = [client.submit(_logged, work, None if logs is None else str(Path(logs) / f"{name}-{k}.log"),
                                 *unit, key=f"{name}-{sweep}-{k}", pure=False)
                   for k, unit in enumerate(units)]
        index = {f.key: k for k, f in enumerate(futures)}
        results: list = [None] * len(units)
        started = time.perf_counter()
        # This client's own event loop: Dask's default is the process's latest client's, which another sweep
        # of this process may close before this one ends (its results then never arrive).
        for future in as_completed(futures, loop=client.loop):
            k = index[future.key]
            if future.status == "error":
                error = future.exception()
                raise RuntimeError(f"{name}: unit {k} {_label(units[k])} failed: {type(error).__name__}: {error}"
                                   ) from error
            results[k] = future.result()
            done += 1
            running = min(width, len(units) - done)
            if progress:
                print(_progress(done, running, len(units), time.perf_counter() - started), file=sys.stderr,
                      flush=True)
        return results
    except (CancelledError, OSError) as e:          # Dask's: a task cancelled, a connection closed
        gone = is_lost(client, e)
        if not gone and not isinstance(e, CancelledError):
            raise
        when = f"in the middle of the sweep {name!r}, with {done} of {len(units)} units done"
        if not gone:
            when = f"or restarted (a unit was cancelled there) {when}"
        raise SchedulerError(lost(address, when, on_lost)) from e
    finally:
        if own:
            disconnect(client)


__all__ = ["SCHEDULER_ENV", "client_for", "run_sweep"]
