"""Which Dask cluster a sweep runs on, checked before any data is read (not in the paper: plumbing).

A sweep (:mod:`pgae_lite.runs.sweep`) runs on this machine, or on the Dask scheduler named by
``scheduler=`` (``--scheduler``) or, without one, by the environment variable ``PGAE_DASK_SCHEDULER``.
Whatever goes wrong there is one sentence, said before a run loads its data:

- :func:`scheduler_address`, the one place that reads the argument and the variable: an address that
  is empty, malformed (``garbage``, ``tcp://``, ``host:notaport``) or of a scheme Dask's scheduler
  does not speak (``http://``) is an :class:`~pgae_lite.util.errors.ArgumentError` naming where it
  came from;
- :func:`connect`: nobody answering within ``CONNECT_SECONDS``, something that is not a Dask
  scheduler, or no worker joined within ``WORKERS_SECONDS`` is a :class:`SchedulerError`;
- :func:`lost`: the sentence for a scheduler lost in the middle of a sweep (what was saved, how to resume);
  :func:`disconnect` closes a client quietly, even when its scheduler is gone.
"""
from __future__ import annotations

import contextlib
import logging
import os
from typing import NamedTuple

from pgae_lite.util.checks import instance_of
from pgae_lite.util.errors import ArgumentError, PGAELiteError

SCHEDULER_ENV = "PGAE_DASK_SCHEDULER"
CONNECT_SECONDS = 10.0       # how long a scheduler may take to answer
WORKERS_SECONDS = 60.0       # how long a sweep waits for its scheduler's first worker
EXAMPLE = "tcp://host:8786"


class SchedulerError(PGAELiteError, RuntimeError):
    """The Dask scheduler of a sweep cannot be reached, has no workers, or was lost during the sweep."""


class Scheduler(NamedTuple):
    """A checked scheduler address and where it was named: ``""`` for an argument, else ``" (from the
    environment variable PGAE_DASK_SCHEDULER)"``, as messages write it after the address."""

    address: str
    origin: str


def schemes() -> tuple[str, ...]:
    """The address schemes a client here can connect by: those of Dask's own registry (tcp, tls, ws, wss,
    inproc) whose connector can be made (not ucx without its package)."""
    import distributed.comm  # noqa: F401 -- registers the backends
    from distributed.comm.registry import backends

    def usable(backend) -> bool:
        try:
            backend.get_connector()
        except Exception:  # noqa: BLE001 -- a scheme Dask lists but cannot use here
            return False
        return True
    return tuple(sorted(s for s, b in backends.items() if usable(b)))


def _cut(text: str, most: int = 80) -> str:
    """``repr(text)``, cut short past ``most`` characters."""
    return repr(text) if len(text) <= most else repr(text[:most - 3]) + "..."


def check_address(address: str, where: str) -> str:
    """``address`` if Dask can read it as a scheduler's (``SCHEME://HOST:PORT``, or ``HOST:PORT`` for tcp);
    else an ArgumentError naming ``where`` it came from and what is allowed."""
    from distributed.comm import parse_address, parse_host_port

    usable = schemes()
    allowed = ", ".join(f"{s}://" for s in usable)
    shown = _cut(address)
    form = f"SCHEME://HOST:PORT, e.g. {EXAMPLE} (the schemes: {allowed}; tcp:// if none)"
    if any(c.isspace() for c in address):
        raise ArgumentError(f"{where} {shown} holds a space; give a Dask scheduler's address: {form}")
    scheme, sep, _ = address.partition("://")
    if sep and not scheme:
        raise ArgumentError(f"{where} {shown} has no scheme before ://; give a Dask scheduler's address: {form}")
    if sep and scheme not in usable:
        raise ArgumentError(f"{where} {shown} has the scheme {scheme[:20]}://, which Dask's scheduler does not "
                            f"speak (a dashboard's http:// address is not the scheduler's); the schemes are: "
                            f"{allowed}")
    try:
        scheme, location = parse_address(address)
        if scheme == "inproc" and location:      # this process's own scheduler: no port
            return address
        host, port = parse_host_port(location)
    except ValueError:
        host, port = "", None
    if not host or not isinstance(port, int) or not 1 <= port <= 65535:
        raise ArgumentError(f"{where} {shown} is not a Dask scheduler's address: give {form}")
    return address


def scheduler_address(scheduler: str | None = None, name: str = "scheduler") -> Scheduler | None:
    """The scheduler a sweep runs on: ``scheduler`` (called ``name`` in messages), else the environment
    variable ``PGAE_DASK_SCHEDULER``, checked (:func:`check_address`); None: this machine."""
    instance_of(name, scheduler, str, f"a Dask scheduler's address, e.g. {EXAMPLE}", optional=True)
    if scheduler is not None:
        if not scheduler.strip():
            raise ArgumentError(f"{name} is empty (an unset variable?); give a Dask scheduler's address, "
                                f"e.g. {EXAMPLE}, or leave {name} out to run here")
        return Scheduler(check_address(scheduler, name), "")
    value = os.environ.get(SCHEDULER_ENV)
    if value is None:
        return None
    where = f"the environment variable {SCHEDULER_ENV}"
    if not value.strip():
        raise ArgumentError(f"{where} is set but empty (an unset variable?); unset it to run here, or set it "
                            f"to a Dask scheduler's address, e.g. {EXAMPLE}")
    return Scheduler(check_address(value, where), f" (from {where})")


def connect(scheduler: Scheduler, connect_seconds: float | None = None, workers_seconds: float | None = None):
    """A Dask client on ``scheduler``, once at least one worker has joined it; else a SchedulerError after
    ``connect_seconds`` (default ``CONNECT_SECONDS``) or ``workers_seconds`` (``WORKERS_SECONDS``)."""
    from distributed import Client
    from distributed.exceptions import WorkerStartTimeoutError

    address, origin = scheduler
    connect_seconds = CONNECT_SECONDS if connect_seconds is None else connect_seconds
    workers_seconds = WORKERS_SECONDS if workers_seconds is None else workers_seconds
    try:
        client = Client(address, timeout=connect_seconds)
    except OSError as e:                    # refused, no such host, no answer: Dask's TimeoutError is an OSError
        raise SchedulerError(f"no Dask scheduler answered at {address}{origin} within {connect_seconds:g} s; "
                             f"start one there (dask scheduler) or correct the address") from e
    except Exception as e:  # noqa: BLE001 -- whatever a server that is not Dask's makes the handshake raise
        raise SchedulerError(f"something answers at {address}{origin}, but not as a Dask scheduler "
                             f"({type(e).__name__}); give the scheduler's address, not its dashboard's") from e
    try:
        client.wait_for_workers(1, timeout=workers_seconds)
    except WorkerStartTimeoutError as e:
        disconnect(client)
        raise SchedulerError(f"no workers joined the Dask scheduler at {address}{origin} within "
                             f"{workers_seconds:g} s; start one (dask worker {address} --nthreads 1) and run "
                             f"again") from e
    except OSError as e:
        disconnect(client)
        raise SchedulerError(lost(address, "while waiting for its workers", "nothing was run")) from e
    return client


def lost(address: str, when: str, saved: str) -> str:
    """One sentence: the scheduler at ``address`` was lost ``when``; ``saved``: what was kept, how to resume."""
    return f"the Dask scheduler at {address} was lost {when}; {saved}"


def is_lost(client, error: BaseException | None = None) -> bool:
    """Whether ``client`` lost its scheduler (``error``: what a future or a call raised, if any)."""
    return client.status != "running" or "connection-lost" in str(error or "")


def disconnect(client) -> None:
    """Close ``client`` (and the local cluster it started, if any); quietly if its scheduler is gone, whose
    reconnection Dask would otherwise log as a traceback."""
    cluster = getattr(client, "cluster", None)
    quiet = is_lost(client)
    loggers = [logging.getLogger(name) for name in list(logging.root.manager.loggerDict)
               if quiet and name.split(".")[0] == "distributed"]      # Dask's, each with its own level
    levels = [logger.level for logger in loggers]
    for logger in loggers:
        logger.setLevel(logging.CRITICAL + 1)
    try:
        with contextlib.suppress(Exception) if quiet else contextlib.nullcontext():
            client.close()
            if cluster is not None:
                cluster.close()
    finally:
        for logger, level in zip(loggers, levels):
            logger.setLevel(level)


__all__ = ["CONNECT_SECONDS", "EXAMPLE", "SCHEDULER_ENV", "WORKERS_SECONDS", "Scheduler", "SchedulerError",
           "check_address", "connect", "disconnect", "is_lost", "lost", "scheduler_address", "schemes"]
