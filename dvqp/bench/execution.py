"""Run bench jobs in this process or a local process pool (``concurrent.futures``).

Rows are handed to ``on_rows`` scene by scene as they finish, so a caller interrupted by
Ctrl-C still holds every finished scene. With a pool, this process runs the first scene
itself (loading, or at a cold start compiling, every backend's kernels once), then forks the
workers (``fork`` where the platform has it), which inherit what it loaded: a worker starts in
milliseconds, and no two processes compile the same kernel. A pool worker that dies (killed
by the OOM killer, say) costs only its own scene: the pool is rebuilt, and the scenes that were
running when it died are run again, each alone; one that kills its worker again is reported
as ``worker lost``. Where the runs went is described by :class:`Where`, which the results
carry: timings of workers that ran side by side are marked ``parallel``, and ``startup`` holds
each worker's start-up.
"""

from __future__ import annotations

import contextlib
import functools
import multiprocessing
import os
import signal
import threading
import time
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import ALL_COMPLETED, FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from dataclasses import asdict, dataclass
from multiprocessing.context import BaseContext

from dvqp.bench.generate import BenchScene, generate_scene
from dvqp.bench.runner import Job, Row, lost_rows, run_job
from dvqp.run.comparison import quiet_worker

Progress = Callable[[int, int, str], None]
"""``progress(done, total, label)``, counting runs (scene × backend)."""
OnRows = Callable[[list[Row]], None]
"""Receives the rows of one finished scene."""
_WARM: set[str] = set()
"""Backends this process has run (their kernels loaded); a forked worker inherits it."""
_STARTUP = 0.0
"""This worker process's start-up, s (:func:`_start_worker`)."""


@dataclass(frozen=True)
class Where:
    """Where the runs went: ``kind`` ``"local"`` (this process or a local pool) or ``"dask"``,
    ``workers`` runs that could go on at the same time (processes, or Dask worker threads), and
    the Dask ``scheduler``'s address (``"local"`` for a LocalCluster, None for local runs),
    and each worker's ``startup``, s: from asking for it (process or cluster start) until it
    could run its first scene (:func:`warm_up`), in the order the workers answered."""

    kind: str
    workers: int
    scheduler: str | None = None
    startup: tuple[float, ...] = ()

    @property
    def parallel(self) -> bool:
        """Several runs could share the machine(s): their timings are noisier."""
        return self.workers > 1

    def as_dict(self) -> dict[str, object]:
        """For the JSON document."""
        return {**asdict(self), "parallel": self.parallel}

    def describe(self) -> str:
        """``local, 1 process (one run at a time)``, ``dask (tcp://…), 4 worker threads (…)``,
        then ``; worker start-up 0.01, 0.02 s`` if known."""
        place = "local" if self.kind == "local" else f"dask ({self.scheduler})"
        unit = {"local": "process", "dask": "worker thread"}[self.kind]
        unit = "worker process" if self.scheduler == "local" else unit
        plural = "" if self.workers == 1 else "es" if unit.endswith("process") else "s"
        how = "in parallel: noisier timings" if self.parallel else "one run at a time"
        started = ", ".join(f"{s:.2f}" for s in self.startup)
        return f"{place}, {self.workers} {unit}{plural} ({how})" + (
            f"; worker start-up {started} s" if started else ""
        )


def local_where(jobs: Sequence[Job], workers: int) -> Where:
    """Where :func:`run_local` runs ``jobs`` with ``workers`` processes."""
    return Where("local", max(1, min(workers, len(jobs))))


def warm_up(job: Job) -> float:
    """Make this process ready to run scenes like ``job``: dvqp imported and each backend's
    kernels loaded (compiled at a cold start), by running ``job`` unless this process (or the
    one it was forked from) has run those backends already. Returns the seconds it took."""
    started = time.perf_counter()
    if not _WARM.issuperset(job.backends):
        run_job(job)
        _WARM.update(job.backends)
    return time.perf_counter() - started


@contextlib.contextmanager
def sigint_deferred() -> Iterator[None]:
    """Ctrl-C held back for the duration and raised after it: ``os.fork`` runs Python hooks
    (logging's lock release) in which a KeyboardInterrupt is printed and ignored, not raised,
    so a Ctrl-C that landed while the pool forked was lost (the bench ran on to exit 0); and a
    LocalCluster whose start it cut short was never closed: its event loop's thread went on
    starting a worker as the bench exited, by Dask's default method once the configuration
    was restored (``spawn``), and that process printed an ``EOFError`` traceback into the
    bench's stderr. A process forked meanwhile (a pool's, a cluster's worker) inherits the
    handler: there Ctrl-C ends it at once, silently (exit 130), as :func:`~dvqp.run.
    comparison.quiet_worker` has it. Outside the main thread (which alone receives Ctrl-C)
    nothing is held."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    held: list[int] = []
    here = os.getpid()

    def hold(signum: int, frame: object) -> None:
        if os.getpid() != here:
            os._exit(130)
        held.append(signum)

    previous = signal.signal(signal.SIGINT, hold)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
        if held:
            raise KeyboardInterrupt


def pool_context() -> BaseContext:
    """``fork`` where the platform has it (workers inherit this process's loaded kernels),
    else the platform's default (each worker warms itself up: :func:`warm_up`)."""
    fork = "fork" in multiprocessing.get_all_start_methods()
    return multiprocessing.get_context("fork" if fork else None)


def generate_local(seed: int, count: int, workers: int) -> list[BenchScene]:
    """:func:`~dvqp.bench.generate.generate_scenes` (the same scenes), drawn by ``workers``
    processes: the first here, the others by a pool forked from here (:func:`pool_context`),
    in chunks."""
    scenes = [generate_scene(seed, 0)]  # the pool forks with what it loaded
    if workers == 1 or count < 3:
        return scenes + [generate_scene(seed, i) for i in range(1, count)]
    pool = ProcessPoolExecutor(workers, mp_context=pool_context(), initializer=quiet_worker)
    try:
        draw = functools.partial(generate_scene, seed)
        with sigint_deferred():  # the pool forks here
            drawn = pool.map(draw, range(1, count), chunksize=max(1, count // (4 * workers)))
        scenes += drawn  # appended as they come, in order: kept if the pool breaks
    except BrokenProcessPool:  # a process died (the OOM killer): the rest drawn here
        _kill(pool)
        return scenes + [generate_scene(seed, i) for i in range(len(scenes), count)]
    except BaseException:
        _kill(pool)
        raise
    pool.shutdown(wait=True)
    return scenes


def run_local(
    jobs: Sequence[Job], workers: int, on_rows: OnRows, progress: Progress | None = None
) -> tuple[float, ...]:
    """Run every job, in this process (``workers`` 1) or in a pool of ``workers`` processes;
    return the pool workers' start-ups, s (:class:`Where`; empty without a pool).

    With a pool, this process runs the first job, then starts the pool, whose processes are
    forked from it (:func:`pool_context`) and each hold the next job queued while running one.
    When a process dies, the pool is rebuilt; the scenes it held are run again, one at a
    time, and a scene whose process dies then too gets :func:`~dvqp.bench.runner.lost_rows`
    (``worker lost``). Ctrl-C (KeyboardInterrupt) kills the pool's processes at once and
    propagates; the rows of the scenes finished before it have been handed to ``on_rows``.
    """
    total, done = sum(len(job.backends) for job in jobs), 0

    def tick(count: int, label: str) -> None:
        nonlocal done
        done += count
        if progress is not None:
            progress(done, total, label)

    def run_here(job: Job) -> None:
        on_rows(run_job(job, lambda backend: tick(1, f"{job.name} {backend}")))
        _WARM.update(job.backends)

    def finished(job: Job, rows: list[Row]) -> None:
        on_rows(rows)
        tick(len(rows), job.name)

    if local_where(jobs, workers).workers == 1:
        for job in jobs:
            run_here(job)
        return ()
    run_here(jobs[0])  # the workers are forked warm from here
    rest, startup = list(jobs[1:]), {}
    while rest:
        suspects, rest = _pool_round(rest, workers, finished, startup, jobs[0])
        for job in suspects:  # alone, so that a death now is its own
            if _pool_round([job], 1, finished, startup, jobs[0])[0]:
                finished(job, lost_rows(job))
    return tuple(startup.values())


def _start_worker(asked: float, job: Job) -> None:
    """A pool process's initializer: quiet on Ctrl-C, warmed up (:func:`warm_up`), its
    start-up since ``asked`` (``time.time()`` in the parent) kept for :func:`_run`."""
    global _STARTUP
    quiet_worker()
    warm_up(job)
    _STARTUP = max(0.0, time.time() - asked)


def _run(job: Job) -> tuple[int, float, list[Row]]:
    """A pool task: this process's id and start-up, and the job's rows."""
    return os.getpid(), _STARTUP, run_job(job)


def _pool_round(
    jobs: Sequence[Job],
    workers: int,
    finished: Callable[[Job, list[Row]], None],
    startup: dict[int, float],
    warm: Job,
) -> tuple[list[Job], list[Job]]:
    """Run ``jobs`` in a new pool of ``workers`` processes (warmed on ``warm``), each holding
    one job queued behind the one it runs, handing each finished one to ``finished`` and each
    process's start-up to ``startup`` (by process id), until done or a process dies (also
    when it dies between a job's end and the next job's hand-over: the pool then refuses
    new jobs, and those it holds are waited for, their results kept).

    Returns the jobs that were running or queued when a process died (they could not finish:
    the pool fails every job it holds) and those not started yet; both empty when all finished.
    """
    todo, running, broken, dead = list(reversed(jobs)), {}, [], False
    pool = ProcessPoolExecutor(
        max_workers=workers,
        mp_context=pool_context(),
        initializer=_start_worker,
        initargs=(time.time(), warm),
    )
    try:
        while (todo or running) and not (broken or dead):
            try:
                with sigint_deferred():  # the first submit forks the pool's processes
                    while todo and len(running) < 2 * workers:
                        running[pool.submit(_run, todo[-1])] = todo[-1]
                        todo.pop()
            except BrokenProcessPool:  # a process died after the last wait: no new job
                dead = True
            wait(running, return_when=ALL_COMPLETED if dead else FIRST_COMPLETED)
            if any(_lost(f) for f in running):
                wait(running)  # a broken pool fails every job it holds, at once
            for future in [f for f in running if f.done()]:
                job = running.pop(future)
                if _lost(future):
                    broken.append(job)
                else:
                    pid, started, rows = future.result()
                    startup.setdefault(pid, started)
                    finished(job, rows)
    except BaseException:
        _kill(pool)
        raise
    pool.shutdown(wait=True)
    return broken, todo[::-1]


def _lost(future: Future[tuple[int, float, list[Row]]]) -> bool:
    """The future is done and failed because its pool lost a process."""
    return future.done() and isinstance(future.exception(), BrokenProcessPool)


def _kill(pool: ProcessPoolExecutor) -> None:
    """Kill the pool's processes now (their scenes are abandoned) and drop its queued jobs."""
    for process in list((getattr(pool, "_processes", None) or {}).values()):
        process.kill()
    pool.shutdown(wait=False, cancel_futures=True)
