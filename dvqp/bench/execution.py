"""Run bench jobs in this process or a local process pool (``concurrent.futures``).

Rows are handed to ``on_rows`` scene by scene as they finish, so a caller interrupted by
Ctrl-C still holds every finished scene. Where the runs went is described by :class:`Where`,
which the results carry: timings of workers that ran side by side are marked ``parallel``.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from concurrent.futures import Future, ProcessPoolExecutor, as_completed
from dataclasses import asdict, dataclass

from dvqp.bench.runner import Job, Row, run_job
from dvqp.comparison import quiet_worker

Progress = Callable[[int, int, str], None]
"""``progress(done, total, label)``, counting runs (scene × backend)."""
OnRows = Callable[[list[Row]], None]
"""Receives the rows of one finished scene."""


@dataclass(frozen=True)
class Where:
    """Where the runs went: ``kind`` ``"local"`` (this process or a local pool) or ``"dask"``,
    ``workers`` runs that could go on at the same time (processes, or Dask worker threads), and
    the Dask ``scheduler``'s address (``"local"`` for a LocalCluster, None for local runs)."""

    kind: str
    workers: int
    scheduler: str | None = None

    @property
    def parallel(self) -> bool:
        """Several runs could share the machine(s): their timings are noisier."""
        return self.workers > 1

    def as_dict(self) -> dict[str, object]:
        """For the JSON document."""
        return {**asdict(self), "parallel": self.parallel}

    def describe(self) -> str:
        """``local, 1 process (one run at a time)``, ``dask (tcp://…), 4 worker threads (…)``."""
        place = "local" if self.kind == "local" else f"dask ({self.scheduler})"
        unit = "process" if self.kind == "local" else "worker thread"
        plural = "" if self.workers == 1 else "es" if unit == "process" else "s"
        how = "in parallel: noisier timings" if self.parallel else "one run at a time"
        return f"{place}, {self.workers} {unit}{plural} ({how})"


def local_where(jobs: Sequence[Job], workers: int) -> Where:
    """Where :func:`run_local` runs ``jobs`` with ``workers`` processes."""
    return Where("local", max(1, min(workers, len(jobs))))


def run_local(
    jobs: Sequence[Job], workers: int, on_rows: OnRows, progress: Progress | None = None
) -> None:
    """Run every job, in this process (``workers`` 1) or in a pool of ``workers`` processes.

    Ctrl-C (KeyboardInterrupt) stops the pool without waiting for it and propagates; the
    rows of the scenes finished before it have been handed to ``on_rows``.
    """
    total, done = sum(len(job.backends) for job in jobs), 0

    def tick(count: int, label: str) -> None:
        nonlocal done
        done += count
        if progress is not None:
            progress(done, total, label)

    if local_where(jobs, workers).workers == 1:
        for job in jobs:
            on_rows(run_job(job, lambda backend, j=job: tick(1, f"{j.name} {backend}")))
        return
    pool = ProcessPoolExecutor(max_workers=workers, initializer=quiet_worker)
    try:
        futures: dict[Future[list[Row]], Job] = {pool.submit(run_job, job): job for job in jobs}
        for future in as_completed(futures):
            on_rows(future.result())
            tick(len(futures[future].backends), futures[future].name)
    except BaseException:
        pool.shutdown(wait=False, cancel_futures=True)
        raise
    pool.shutdown(wait=True)
