"""Run bench jobs on a Dask distributed cluster: an existing scheduler or a LocalCluster.

Dask is optional (``pip install 'dvqp[dask]'``): it is imported only by
:func:`import_distributed`, when a cluster is asked for. The workers run
:func:`dvqp.bench.runner.run_job` on the scene text, so they need dvqp (and the named
backends) installed; they give the same outcomes as a local run, only their timings differ.
"""

from __future__ import annotations

import contextlib
import logging
from collections.abc import Iterator, Sequence
from types import ModuleType
from typing import Any

from dvqp.bench.execution import OnRows, Progress, Where
from dvqp.bench.runner import Job, run_job
from dvqp.errors import DvqpError, one_line

CONNECT_TIMEOUT = "10s"
"""How long to wait for an existing scheduler."""


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
        ``LocalCluster`` of ``workers`` single-threaded workers in this process (threads:
        quick to start and stopped cleanly by Ctrl-C, but sharing the interpreter).
    workers
        Workers of a LocalCluster (ignored for an existing scheduler).

    Raises
    ------
    DaskUnavailableError
        Dask is not installed.
    DvqpError
        ``scheduler <address>: cannot connect: <reason>``, or ``… no worker within 10s``.
    """
    dd = import_distributed()
    logger = logging.getLogger("distributed")
    with contextlib.ExitStack() as stack:
        stack.callback(logger.setLevel, logger.level)
        logger.setLevel(logging.ERROR)  # no info lines on the cluster's start and stop
        try:
            if scheduler == "local":
                cluster = stack.enter_context(
                    dd.LocalCluster(n_workers=workers, threads_per_worker=1,
                                    processes=False, dashboard_address=None)
                )  # fmt: skip
                client = stack.enter_context(dd.Client(cluster))
            else:
                client = stack.enter_context(dd.Client(scheduler, timeout=CONNECT_TIMEOUT))
        except (OSError, TimeoutError, ValueError) as exc:
            reason = one_line(str(exc) or type(exc).__name__)
            raise DvqpError(f"scheduler {scheduler}: cannot connect: {reason}") from exc
        try:
            client.wait_for_workers(1, timeout=CONNECT_TIMEOUT)
        except (OSError, TimeoutError) as exc:
            raise DvqpError(f"scheduler {scheduler}: no worker within {CONNECT_TIMEOUT}") from exc
        threads = int(sum(client.nthreads().values()))
        yield client, Where("dask", threads, scheduler)


def run_dask(
    client: Any, jobs: Sequence[Job], on_rows: OnRows, progress: Progress | None = None
) -> None:
    """Run every job on the cluster of ``client``, handing each scene's rows to ``on_rows``.

    Ctrl-C (KeyboardInterrupt) cancels what has not finished and propagates. A job that fails
    on a worker for another reason than a failed run (e.g. dvqp missing there) raises
    ``DvqpError("dask: <scene>: <error>")``.
    """
    dd = import_distributed()
    total, done = sum(len(job.backends) for job in jobs), 0
    futures = {client.submit(run_job, job, pure=False): job for job in jobs}
    try:
        for future in dd.as_completed(list(futures)):
            job = futures[future]
            try:
                rows = future.result()
            except DvqpError:
                raise
            except Exception as exc:
                reason = f"{type(exc).__name__}: {one_line(str(exc))}"
                raise DvqpError(f"dask: {job.name}: {reason}") from exc
            on_rows(rows)
            done += len(job.backends)
            if progress is not None:
                progress(done, total, job.name)
    except BaseException:
        client.cancel(list(futures))
        raise
