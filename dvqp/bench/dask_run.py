"""Run bench jobs on a Dask distributed cluster: an existing scheduler or a LocalCluster.

A scene whose worker dies is run again by the scheduler on another worker (and once more if it
raised: ``retries=1``); one that killed its workers too often (Dask's ``allowed-failures``) is
reported as ``worker lost``, one that runs longer than the scene timeout as ``timed out``.
When no worker is left for :data:`WORKER_WAIT` seconds the suite stops
(:class:`WorkersLostError`) instead of waiting for ever.

Dask is optional (``pip install 'dvqp[dask]'``): it is imported only by
:func:`import_distributed`, when a cluster is asked for. The workers run
:func:`dvqp.bench.runner.run_job` on the scene text, so they need dvqp (and the named
backends) installed; they give the same outcomes as a local run, only their timings differ.
Before the first scene, :func:`warm_workers` has every worker load dvqp's compiled kernels
(``Client.run``) and reports each one's start-up; a LocalCluster's worker processes are forked
from this process (where the platform has ``fork``), which has run the first scene already,
so they start with its kernels loaded.
"""

from __future__ import annotations

import asyncio
import contextlib
import gc
import logging
import math
import time
from collections.abc import Callable, Iterator, Sequence
from types import ModuleType
from typing import Any

from dvqp.bench.execution import (
    OnRows,
    Progress,
    Where,
    pool_context,
    sigint_deferred,
    warm_up,
)
from dvqp.bench.runner import Job, Row, lost_rows, run_job
from dvqp.errors import DvqpError, one_line

CONNECT_TIMEOUT = "10s"
"""How long to wait for an existing scheduler."""
WORKER_WAIT = 10.0
"""How long to wait for a worker, s: at the start, and when every worker has left."""
SCENE_TIMEOUT = 600.0
"""How long a scene may run on a worker by default, s (all its backends)."""
POLL = 0.5
"""How often the scheduler is asked what runs where, s."""
WAKE = 0.05
"""How often finished scenes are collected, s. The workers never wait for it: each holds its
next scene while it runs one (Dask's queuing)."""
LOCAL_WORKER_CONFIG = {
    "distributed.worker.profile.enabled": False,
    "distributed.worker.memory.monitor-interval": "1s",
}
"""A LocalCluster's workers: no statistical profiler (a thread that samples the running
task's stack every 10 ms, taking the GIL from it: scenes ran ~25 % slower than in a process
pool) and their memory checked every second, not ten times a second (a scene's memory does
not grow). An existing cluster's workers keep their own configuration."""


class WorkersLostError(DvqpError):
    """Every worker left the cluster during a suite; ``suite`` (set by
    :func:`~dvqp.bench.suite.run_suite`) holds the scenes finished before."""

    suite: Any = None


class DaskUnavailableError(DvqpError, ImportError):
    """Dask's distributed scheduler is not installed."""

    def __init__(self) -> None:
        super().__init__("needs Dask: pip install 'dvqp[dask]'")


def _load_distributed() -> ModuleType:
    """Import ``dask.distributed`` (ImportError if absent; tests replace this to simulate it)."""
    import dask.distributed

    return dask.distributed


def import_distributed() -> ModuleType:
    """The ``dask.distributed`` module; :class:`DaskUnavailableError` if it is not installed."""
    try:
        return _load_distributed()
    except ImportError as exc:
        raise DaskUnavailableError() from exc


@contextlib.contextmanager
def dask_client(scheduler: str, workers: int = 1) -> Iterator[tuple[Any, Where]]:
    """A connected ``dask.distributed.Client`` and where it runs; both closed at the end.

    Parameters
    ----------
    scheduler
        A scheduler's address (``tcp://host:8786``), or ``"local"`` to start a
        ``LocalCluster`` of ``workers`` single-threaded worker processes, forked from this one
        where the platform can (:func:`~dvqp.bench.execution.pool_context`).
    workers
        Workers of a LocalCluster (ignored for an existing scheduler).

    Raises
    ------
    DaskUnavailableError
        Dask is not installed.
    DvqpError
        ``scheduler <address>: cannot connect: <reason>``, or ``… no worker within 10 s``.
    """
    dd = import_distributed()
    import dask  # present with dask.distributed

    with contextlib.ExitStack() as stack:
        _quiet_logs(stack)
        try:
            if scheduler == "local":
                method = pool_context().get_start_method()  # for the cluster's whole life:
                key = "distributed.worker.multiprocessing-method"  # a worker restarted too
                stack.enter_context(dask.config.set({key: method, **LOCAL_WORKER_CONFIG}))
                with sigint_deferred():  # a start cut short is never closed (below)
                    cluster = stack.enter_context(
                        dd.LocalCluster(
                            n_workers=workers,
                            threads_per_worker=1,
                            processes=True,
                            dashboard_address=None,
                        )
                    )
                client = stack.enter_context(dd.Client(cluster))
            else:
                client = stack.enter_context(dd.Client(scheduler, timeout=CONNECT_TIMEOUT))
        except (OSError, TimeoutError, ValueError) as exc:
            reason = one_line(str(exc) or type(exc).__name__)
            raise DvqpError(f"scheduler {scheduler}: cannot connect: {reason}") from exc
        try:
            client.wait_for_workers(1, timeout=WORKER_WAIT)
        except (OSError, TimeoutError) as exc:
            raise DvqpError(f"scheduler {scheduler}: no worker within {WORKER_WAIT:g} s") from exc
        threads = int(sum(client.nthreads().values()))
        yield client, Where("dask", threads, scheduler)


def warm_workers(client: Any, job: Job, asked: float) -> tuple[float, ...]:
    """Warm every worker of ``client`` up on ``job`` (:func:`~dvqp.bench.execution.warm_up`,
    by ``Client.run``); each one's start-up, s: from ``asked`` (``time.time()`` here, e.g.
    before the cluster started) until it was warm, in the order of the workers' addresses."""
    try:
        done = client.run(_warmed, job, asked)
    except Exception as exc:  # e.g. dvqp missing on a worker
        reason = f"{type(exc).__name__}: {one_line(str(exc))}"
        raise DvqpError(f"dask: warming the workers up on {job.name}: {reason}") from exc
    return tuple(done[address] for address in sorted(done))


def _warmed(job: Job, asked: float) -> float:
    """On a worker: :func:`~dvqp.bench.execution.warm_up`, then the seconds since ``asked``."""
    warm_up(job)
    return max(0.0, time.time() - asked)


def _quiet_logs(stack: contextlib.ExitStack) -> None:
    """Distributed's loggers (each has its own level) to CRITICAL and asyncio's and tornado's
    off for the stack's life: no info lines on the cluster's start and stop, no warning when a
    result must be recomputed, no "Task exception was never retrieved" for a fetch given up, no
    traceback of distributed's own ``sync`` when a Ctrl-C lands before its future exists
    (tornado logs that callback's NameError, distributed 2026.8); what matters
    reaches the user as dvqp's own lines. Dead tasks are collected before the levels return
    (a nanny's start cut short by Ctrl-C leaves a failed task, reported when collected); after
    an exception they stay raised (the cut-short start goes on logging in its threads)."""
    known = logging.root.manager.loggerDict
    names = [n for n in known if n.split(".")[0] == "distributed"]
    off = ["asyncio", "tornado", *(n for n in known if n.startswith("tornado."))]
    for name, level in [
        *((n, logging.CRITICAL) for n in ["distributed", *names]),
        *((n, logging.CRITICAL + 1) for n in off),
    ]:
        logger = logging.getLogger(name)
        stack.push(_restorer(logger, logger.level))
        logger.setLevel(level)
    stack.callback(gc.collect)  # first on the way out: the levels are still raised


def _restorer(logger: logging.Logger, level: int) -> Callable[..., bool]:
    """An exit callback giving ``logger`` its ``level`` back, unless the block ended in an
    exception (Ctrl-C while a cluster starts): its threads may still log on the way out."""

    def restore(exc_type: type[BaseException] | None, *_: object) -> bool:
        if exc_type is None:
            logger.setLevel(level)
        return False

    return restore


def run_dask(
    client: Any,
    jobs: Sequence[Job],
    on_rows: OnRows,
    progress: Progress | None = None,
    timeout: float = SCENE_TIMEOUT,
) -> None:
    """Run every job on the cluster of ``client``, handing each scene's rows to ``on_rows``.

    A scene running longer than ``timeout`` s (from when a worker took it) is cancelled and
    gets :func:`~dvqp.bench.runner.lost_rows` ``timed out after <timeout> s``; one whose
    workers died too often (``KilledWorker``) ``worker lost``. Ctrl-C (KeyboardInterrupt)
    cancels what has not finished and propagates. A job that fails on a worker for another
    reason than a failed run (e.g. dvqp missing there) raises ``DvqpError("dask: <scene>:
    <error>")``; no worker left for :data:`WORKER_WAIT` s raises :class:`WorkersLostError`.

    Finished scenes are collected from one ``as_completed`` every :data:`WAKE` s. Waiting on
    the remaining futures after each one instead (``wait(..., FIRST_COMPLETED)``) had the
    cluster's event loop in this process register on every one of them again: on a
    200-scene suite that loop's thread used 2.3 s of CPU, 1.0 s now, taken from the cores the
    workers run on.
    """
    dd = import_distributed()
    total, done = sum(len(job.backends) for job in jobs), 0
    futures = {client.submit(run_job, job, pure=False, retries=1): job for job in jobs}
    remaining, watch = dict(futures), _Watch(client, timeout)
    completed = dd.as_completed(list(futures), loop=client.loop)  # a cancelled one comes too
    try:
        while remaining:
            finished = [f for f in completed.next_batch(block=False) if f in remaining]
            late = [f for f in watch.overdue(remaining) if f not in finished]
            client.cancel(late)
            for future in [*finished, *late]:
                job = remaining.pop(future)
                on_rows(
                    _rows(dd, future, job)
                    if future in finished
                    else lost_rows(job, f"timed out after {timeout:g} s")
                )
                done += len(job.backends)
                if progress is not None:
                    progress(done, total, job.name)
            if remaining and not finished and not late:
                time.sleep(WAKE)
    except BaseException:
        client.cancel(list(futures))
        raise


def _rows(dd: ModuleType, future: Any, job: Job) -> list[Row]:
    """The rows of a finished job: its result, or ``worker lost`` if its workers died (also
    when the result was held by a worker that left before it was fetched: the scheduler would
    wait for a worker to compute it again, for ever if none is left)."""
    try:
        return future.result(timeout=WORKER_WAIT)
    except DvqpError:
        raise
    except (dd.KilledWorker, TimeoutError, asyncio.TimeoutError):
        return lost_rows(job)
    except Exception as exc:
        reason = f"{type(exc).__name__}: {one_line(str(exc))}"
        raise DvqpError(f"dask: {job.name}: {reason}") from exc


class _Watch:
    """What the scheduler runs: when each job began on a worker (first seen), and since when
    no worker is left."""

    def __init__(self, client: Any, timeout: float) -> None:
        self.client, self.timeout = client, timeout
        self.started: dict[str, float] = {}
        self.alone: float | None = None  # since when no worker is left
        self.asked = -math.inf  # when the scheduler was last asked

    def overdue(self, futures: dict[Any, Job]) -> list[Any]:
        """The futures running longer than the timeout; :class:`WorkersLostError` when no
        worker has been left for :data:`WORKER_WAIT` s. The scheduler is asked at most every
        :data:`POLL` s (none between)."""
        now = time.monotonic()
        if now - self.asked < POLL:
            return []
        self.asked, processing = now, self.client.processing()
        if processing:
            self.alone = None
        elif self.alone is None:
            self.alone = now
        elif now - self.alone > WORKER_WAIT:
            left = sum(1 for f in futures if f.status == "pending")
            raise WorkersLostError(f"no worker left for {WORKER_WAIT:g} s; {left} scenes not run")
        for keys in processing.values():
            for key in keys:
                self.started.setdefault(str(key), now)
        return [f for f in futures if now - self.started.get(str(f.key), now) > self.timeout]
