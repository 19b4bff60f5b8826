"""Work fanned out on Dask (``dask.distributed``): a :class:`~distributed.LocalCluster` of worker processes on this
machine, or the scheduler of a cluster the user runs (``--scheduler tcp://host:8786``).

:func:`fan_out` sends the shared, read-only part of a run once to every worker (the station and its rules), then the
pieces of work as tasks; results come back in the order of the pieces, whatever finished first, so a report is the
same with any number of workers. A worker that dies loses only the tasks it held: the scheduler gives them to another
worker (and a task that fails is retried), so one lost worker costs time, not results.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from typing import Any, TypeVar

from liansuo.proving.progress import Advance

T = TypeVar("T")
R = TypeVar("R")
RETRIES = 2  # a task is tried again this many times (on another worker if its own died)
CONNECT_S = 20  # how long to try to reach a scheduler


class SpreadError(Exception):
    """The cluster could not be reached or started: the message says what to do."""


@contextmanager
def client(workers: int, scheduler: str | None) -> Iterator[Any]:
    """A Dask client: on the cluster at ``scheduler``, or on ``workers`` local worker processes of one thread each
    (the simulations are pure Python: threads would share one interpreter lock)."""
    from dask.distributed import Client, LocalCluster

    if scheduler:
        try:
            c = Client(scheduler, timeout=CONNECT_S)  # type: ignore[no-untyped-call]
        except (OSError, TimeoutError, ValueError) as exc:
            raise SpreadError(f"cannot reach the Dask scheduler at {scheduler} ({exc}); start one with 'dask "
                              "scheduler' and workers with 'dask worker ADDRESS' ('liansuo docs cluster'), or leave "
                              "out --scheduler to run here") from None
        with c:
            yield c
        return
    from liansuo.proving.noprofiler import NoProfiler

    # the dashboard on any free port; the workers' chatter when the cluster shuts down is silenced
    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,  # type: ignore[no-untyped-call]
                           dashboard_address=":0", silence_logs=logging.CRITICAL)
    with cluster, Client(cluster) as c:  # type: ignore[no-untyped-call]
        c.register_plugin(NoProfiler())  # on every worker, and on any its nanny starts again
        yield c


def fan_out(shared: Any, pieces: Sequence[T], run: Callable[[Any, T], R], *, workers: int, scheduler: str | None,
            advance: Advance, size: Callable[[T], int] = lambda piece: 1) -> list[R]:
    """``run(shared, piece)`` for every piece on the cluster; results in the order of ``pieces``. ``advance`` is told
    ``size(piece)`` as each comes back. ``run`` must be a module-level function (workers import it)."""
    from dask.distributed import as_completed

    with client(workers, scheduler) as c:
        handle = c.scatter(shared, broadcast=True)
        futures = {c.submit(run, handle, piece, retries=RETRIES, pure=False): i for i, piece in enumerate(pieces)}
        results: list[Any] = [None] * len(pieces)
        for fut in as_completed(futures):  # type: ignore[no-untyped-call]
            i = futures[fut]
            results[i] = fut.result()
            advance(size(pieces[i]))
        return results


def deal(items: Sequence[T], hands: int) -> list[list[int]]:
    """The indices of ``items`` dealt round into ``hands`` piles (item i to pile i mod hands): neighbours in a plan are
    often alike in cost, so dealing keeps the piles even."""
    hands = max(1, min(hands, len(items)))
    return [list(range(h, len(items), hands)) for h in range(hands)]
