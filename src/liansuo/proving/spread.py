"""Work fanned out on Dask (``dask.distributed``): a :class:`~distributed.LocalCluster` of worker processes on this
machine, or the scheduler of a cluster the user runs (``--scheduler tcp://host:8786``).

:func:`fan_out` sends the shared, read-only part of a run once to every worker (the station and its rules), then the
pieces of work as tasks; results come back in the order of the pieces, whatever finished first, so a report is the
same with any number of workers. A worker that dies loses only the tasks it held: the scheduler gives them to another
worker (and a task that fails is retried), so one lost worker costs time, not results.
"""

from __future__ import annotations

import argparse
import logging
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from typing import Any, TypeVar

from liansuo.kit.arguments import positive_number
from liansuo.proving.progress import Advance

T = TypeVar("T")
R = TypeVar("R")
RETRIES = 2  # a task is tried again this many times (on another worker if its own died)
WAIT_S = 20.0  # how long to wait for a scheduler to answer, and then for its first worker (--cluster-wait)
HERE = "or leave out --scheduler to run here"


class SpreadError(Exception):
    """The cluster could not be reached, had no worker, or lost its workers: one line that says what to do."""


def add_wait_option(sp: argparse.ArgumentParser) -> None:
    """``--cluster-wait SECONDS``, beside ``--workers`` and ``--scheduler``."""
    sp.add_argument("--cluster-wait", type=positive_number, default=WAIT_S, metavar="S",
                    help=f"with --scheduler: wait at most S seconds for the scheduler to answer and then for a worker "
                    f"to join (default {WAIT_S:g}); 'liansuo docs cluster'")


@contextmanager
def client(workers: int, scheduler: str | None, wait_s: float = WAIT_S) -> Iterator[Any]:
    """A Dask client: on the cluster at ``scheduler``, or on ``workers`` local worker processes of one thread each
    (the simulations are pure Python: threads would share one interpreter lock). A scheduler that does not answer
    within ``wait_s``, one that has no worker after ``wait_s`` more, and a cluster that loses the work (its last
    worker killed) raise :class:`SpreadError`."""
    from dask.distributed import Client, LocalCluster

    if scheduler:
        try:
            c = Client(scheduler, timeout=wait_s)  # type: ignore[no-untyped-call]
        except ValueError as exc:  # not an address
            raise SpreadError(f"--scheduler {scheduler} is not the address of a Dask scheduler ({exc}); give one "
                              f"as tcp://HOST:8786, {HERE}") from None
        except (OSError, TimeoutError):
            raise SpreadError(f"no Dask scheduler answers at {scheduler} (waited {wait_s:g} s); start one with 'dask "
                              "scheduler' and workers with 'dask worker ADDRESS' ('liansuo docs cluster'), check the "
                              f"address and the firewall, {HERE}") from None
        with c:
            try:
                c.wait_for_workers(1, timeout=wait_s)
            except TimeoutError:
                raise SpreadError(f"the Dask scheduler at {scheduler} has no worker (none joined within {wait_s:g} "
                                  f"s); start some with 'dask worker {scheduler}' ('liansuo docs cluster'), {HERE}"
                                  ) from None
            with lost_work(f"the cluster at {scheduler}", "start workers again with 'dask worker "
                           f"{scheduler}' and run the command again, {HERE}"):
                yield c
        return
    from liansuo.proving.noprofiler import NoProfiler

    # the scheduler's HTTP server (the dashboard, with bokeh; health and metrics) on a free port of this machine
    # only, as every port the cluster opens; the workers' chatter when the cluster shuts down is silenced
    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,  # type: ignore[no-untyped-call]
                           host="127.0.0.1", dashboard_address="127.0.0.1:0", silence_logs=logging.CRITICAL)
    with cluster, Client(cluster) as c:  # type: ignore[no-untyped-call]
        c.register_plugin(NoProfiler())  # on every worker, and on any its nanny starts again
        with lost_work("the local cluster", "run the command again, with fewer --workers if memory is short, "
                       "or without --workers"):
            yield c


@contextmanager
def lost_work(where: str, what_to_do: str) -> Iterator[None]:
    """Dask's errors when a cluster loses what a run needs as a :class:`SpreadError`: the workers that held the
    station all died (the work is cancelled), a task killed worker after worker, or the scheduler went away."""
    from distributed import CancelledError
    from distributed.comm.core import CommClosedError
    from distributed.scheduler import KilledWorker

    try:
        yield
    except (CancelledError, KilledWorker, CommClosedError, TimeoutError) as exc:
        why = ("a task killed every worker that ran it" if isinstance(exc, KilledWorker) else
               "lost the connection to its scheduler" if isinstance(exc, (CommClosedError, TimeoutError)) else
               "lost its last worker (killed, or out of memory) and the work with it")
        raise SpreadError(f"{where} {why}; nothing was reported: {what_to_do}") from None


def fan_out(shared: Any, pieces: Sequence[T], run: Callable[[Any, T], R], *, workers: int, scheduler: str | None,
            advance: Advance, size: Callable[[T], int] = lambda piece: 1, wait_s: float = WAIT_S) -> list[R]:
    """``run(shared, piece)`` for every piece on the cluster; results in the order of ``pieces``. ``advance`` is told
    ``size(piece)`` as each comes back. ``run`` must be a module-level function (workers import it)."""
    from dask.distributed import as_completed

    with client(workers, scheduler, wait_s) as c:
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
