"""The local cluster's workers without Dask's statistical profiler.

A Dask worker samples the stack of the task it runs every 10 ms, for the dashboard's profile. On verify's deep stacks
of pure Python that costs about a quarter of the worker's time: a sample of hub200's units (every 60th, 235 units)
took 75.9 s on one worker with it, 58.4 s without and 56.1 s in one process; on two workers 41.7 s with it and 34.1 s
without. The whole hub200 test on two workers went from 2,630 to 1,764 s, with the same report.
:func:`proving.spread.client` registers :class:`NoProfiler` on the local cluster it starts; the workers of a cluster
the user runs keep their own settings (docs/cluster.md says how to turn it off there).
"""

from __future__ import annotations

from typing import Any

from distributed import WorkerPlugin

PROFILER_CALLBACKS = ("profile", "profile-cycle")  # the periodic callbacks of distributed.Worker's profiler


class NoProfiler(WorkerPlugin):
    """Stops the profiler of every worker it is registered on, and of any worker that joins later (a nanny
    restarting its worker)."""

    name = "liansuo-no-profiler"
    idempotent = True

    def setup(self, worker: Any) -> None:
        for name in PROFILER_CALLBACKS:
            pc = worker.periodic_callbacks.pop(name, None)
            if pc is not None:
                pc.stop()
