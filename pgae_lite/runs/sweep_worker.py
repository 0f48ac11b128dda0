"""A sweep's worker, set up for these trainings however it was started (no paper section: plumbing).

:func:`pgae_lite.runs.sweep.run_sweep` registers :class:`OneCoreWorker` on its cluster, so every
worker, the local cluster's and those started by hand on a lab's machines (and those that join
later), runs its units on one torch thread with glibc's malloc thresholds raised.
"""
from __future__ import annotations

from distributed.diagnostics.plugin import WorkerPlugin


class OneCoreWorker(WorkerPlugin):
    """Set up every worker of a sweep, however it was started: one torch thread, and glibc's
    malloc thresholds raised.

    A Dask nanny starts its worker with ``MALLOC_TRIM_THRESHOLD_=65536`` (to give memory back to
    the system quickly). glibc then never raises its mmap threshold, so every tensor over
    128 KiB is mapped and unmapped afresh, and a training allocates thousands of those a second:
    one training took 1.9 times as long on such a worker as in a plain process
    (``results/history/sweep_engine-malloc-trim.json``).
    """

    def setup(self, worker) -> None:
        import ctypes
        import ctypes.util

        import torch

        torch.set_num_threads(1)           # one core per worker: these networks gain nothing from two
        libc = ctypes.util.find_library("c")
        mallopt = getattr(ctypes.CDLL(libc), "mallopt", None) if libc else None
        if mallopt is not None:            # glibc: M_MMAP_THRESHOLD (-3), M_TRIM_THRESHOLD (-1)
            mallopt(-3, 32 * 2**20)        # blocks up to 32 MiB come from the heap, reused
            mallopt(-1, 64 * 2**20)        # and the heap is trimmed past 64 MiB free


__all__ = ["OneCoreWorker"]
