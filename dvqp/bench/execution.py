"""Run bench jobs in this process or a local process pool (``concurrent.futures``).

Rows are handed to ``on_rows`` scene by scene as they finish, so a caller interrupted by
Ctrl-C still holds every finished scene. A pool worker that dies (killed by the OOM killer, say)
costs only its own scene: the pool is rebuilt, and the scenes that were running when it died are
run again, each alone; one that kills its worker again is reported as ``worker lost``. Where the
runs went is described by :class:`Where`, which the results carry: timings of workers that ran
side by side are marked ``parallel``.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from dataclasses import asdict, dataclass

from dvqp.bench.runner import Job, Row, lost_rows, run_job
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

    The pool runs one scene per process at a time. When a process dies, the pool is rebuilt;
    the scenes it was running are run again, one at a time, and a scene whose process dies
    then too gets :func:`~dvqp.bench.runner.lost_rows` (``worker lost``). Ctrl-C
    (KeyboardInterrupt) kills the pool's processes at once and propagates; the rows of the
    scenes finished before it have been handed to ``on_rows``.
    """
    total, done = sum(len(job.backends) for job in jobs), 0

    def tick(count: int, label: str) -> None:
        nonlocal done
        done += count
        if progress is not None:
            progress(done, total, label)

    def finished(job: Job, rows: list[Row]) -> None:
        on_rows(rows)
        tick(len(rows), job.name)

    if local_where(jobs, workers).workers == 1:
        for job in jobs:
            on_rows(run_job(job, lambda backend, j=job: tick(1, f"{j.name} {backend}")))
        return
    rest = list(jobs)
    while rest:
        suspects, rest = _pool_round(rest, workers, finished)
        for job in suspects:  # alone, so that a death now is its own
            if _pool_round([job], 1, finished)[0]:
                finished(job, lost_rows(job))


def _pool_round(
    jobs: Sequence[Job], workers: int, finished: Callable[[Job, list[Row]], None]
) -> tuple[list[Job], list[Job]]:
    """Run ``jobs`` in a new pool of ``workers`` processes, one job per process at a time,
    handing each finished one to ``finished``, until they are done or a process dies.

    Returns the jobs that were running when a process died (they could not finish: the pool
    fails every job it holds) and those not started yet; both empty when every job finished.
    """
    todo, running, broken = list(reversed(jobs)), {}, []
    pool = ProcessPoolExecutor(max_workers=workers, initializer=quiet_worker)
    try:
        while (todo or running) and not broken:
            while todo and len(running) < workers:
                job = todo.pop()
                running[pool.submit(run_job, job)] = job
            wait(running, return_when=FIRST_COMPLETED)
            if any(_lost(f) for f in running):
                wait(running)  # a broken pool fails every job it holds, at once
            for future in [f for f in running if f.done()]:
                job = running.pop(future)
                if _lost(future):
                    broken.append(job)
                else:
                    finished(job, future.result())
    except BaseException:
        _kill(pool)
        raise
    pool.shutdown(wait=True)
    return broken, todo[::-1]


def _lost(future: Future[list[Row]]) -> bool:
    """The future is done and failed because its pool lost a process."""
    return future.done() and isinstance(future.exception(), BrokenProcessPool)


def _kill(pool: ProcessPoolExecutor) -> None:
    """Kill the pool's processes now (their scenes are abandoned) and drop its queued jobs."""
    for process in list((getattr(pool, "_processes", None) or {}).values()):
        process.kill()
    pool.shutdown(wait=False, cancel_futures=True)
