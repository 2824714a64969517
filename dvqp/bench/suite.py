"""Run a suite of generated scenes with every backend, here or on Dask, and sum it up:
:func:`run_suite`, what ``dvqp bench`` calls after its checks."""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import Any

from dvqp.bench.dask_run import SCENE_TIMEOUT, WorkersLostError, dask_client, run_dask, warm_workers
from dvqp.bench.execution import Progress, Where, local_where, run_local
from dvqp.bench.generate import BenchScene
from dvqp.bench.output import Suite
from dvqp.bench.runner import Job, Row
from dvqp.bench.summary import SHIFT_US, qp_disagreement, summarize_backends


class BenchInterrupted(KeyboardInterrupt):
    """Ctrl-C during a suite (a ``KeyboardInterrupt``); ``suite`` holds the scenes finished
    before it, so they can still be written."""

    def __init__(self, suite: Suite) -> None:
        super().__init__()
        self.suite = suite


def run_suite(
    scenes: Sequence[BenchScene],
    backends: Sequence[str],
    *,
    seed: int,
    workers: int = 1,
    scheduler: str | None = None,
    progress: Progress | None = None,
    ready: Callable[[Where], None] | None = None,
    on_scene: Callable[[list[Row]], None] | None = None,
    scene_timeout: float = SCENE_TIMEOUT,
    shift: float = SHIFT_US,
    options: dict[str, dict[str, Any]] | None = None,
    tier: str = "default",
) -> Suite:
    """Run every scene with every backend and sum the runs up per backend.

    ``scenes`` come from :func:`~dvqp.bench.generate.generate_scenes` with ``seed`` (reported),
    ``backends`` are resolver names checked by the caller. ``scheduler`` None runs them in
    ``workers`` local processes, else on a Dask scheduler at that address, or on a LocalCluster
    of ``workers`` for ``"local"``. ``progress(done, total, label)`` counts runs; ``ready(where)``
    is called once where the runs go is ready (a scheduler reached), before the first run;
    ``on_scene(rows)`` with the rows of each scene as it finishes (e.g. to save them at once).
    ``scene_timeout``: on Dask, how long a scene may run (s); ``shift``: of the shifted
    geometric means, µs; ``options``: settings by backend (``--solver-option``) over the
    settings ``tier``'s (:mod:`solvers.tiers`).

    Raises
    ------
    BenchInterrupted
        Ctrl-C; it carries the suite of the finished scenes.
    WorkersLostError
        Every Dask worker left; its ``suite`` holds the finished scenes.
    DaskUnavailableError, DvqpError
        Dask is missing, or the scheduler cannot be reached.
    """
    jobs = [
        Job(s.index, s.name, s.text, tuple(backends), dict(options or {}), tier)
        for s in longest_first(scenes)
    ]
    rows: list[Row] = []

    def finished(scene_rows: list[Row]) -> None:
        rows.extend(scene_rows)
        if on_scene is not None:
            on_scene(scene_rows)

    where = local_where(jobs, workers)
    where = where if scheduler is None else Where("dask", where.workers, scheduler)
    try:
        if scheduler is None:
            if ready is not None:
                ready(where)
            where = replace(where, startup=run_local(jobs, workers, finished, progress))
        else:
            here = jobs[:1] if scheduler == "local" else []  # then the workers fork warm
            if here and ready is not None:
                ready(where)
            run_local(here, 1, finished, _shifted(progress, 0, jobs))
            asked = time.time()
            with dask_client(scheduler, workers) as (client, where):
                if not here and ready is not None:
                    ready(where)
                if jobs:
                    where = replace(where, startup=warm_workers(client, jobs[0], asked))
                rest = _shifted(progress, len(here) * len(backends), jobs)
                run_dask(client, jobs[len(here) :], finished, rest, scene_timeout)
    except KeyboardInterrupt as exc:
        suite = make_suite(rows, backends, seed, len(scenes), where, shift, interrupted=True)
        raise BenchInterrupted(suite) from exc
    except WorkersLostError as exc:
        exc.suite = make_suite(rows, backends, seed, len(scenes), where, shift, interrupted=True)
        raise
    return make_suite(rows, backends, seed, len(scenes), where, shift)


def longest_first(scenes: Sequence[BenchScene]) -> list[BenchScene]:
    """The order the scenes are handed out in: the shortest first (run alone, here, when the
    workers are forked warm from this process: the least time with one process busy), then
    the longest first (the last to finish are short: the workers end together). The suite's
    rows are sorted by scene index whatever the order."""
    if len(scenes) < 2:
        return list(scenes)
    shortest = min(scenes, key=lambda s: (s.steps, s.index))
    rest = sorted((s for s in scenes if s is not shortest), key=lambda s: (-s.steps, s.index))
    return [shortest, *rest]


def _shifted(progress: Progress | None, before: int, jobs: Sequence[Job]) -> Progress | None:
    """``progress`` of a part of the runs: ``before`` runs done already, of all ``jobs``'."""
    total = sum(len(job.backends) for job in jobs)
    if progress is None:
        return None
    return lambda done, _, label: progress(done + before, total, label)


def make_suite(
    rows: Sequence[Row],
    backends: Sequence[str],
    seed: int,
    count: int,
    where: Where,
    shift: float = SHIFT_US,
    interrupted: bool = False,
) -> Suite:
    """The :class:`~dvqp.bench.output.Suite` of ``rows``, sorted by scene index and backend."""
    order = {b: i for i, b in enumerate(backends)}
    ordered = sorted(rows, key=lambda r: (r["index"], order.get(r["backend"], len(order))))
    return Suite(
        seed=seed,
        count=count,
        backends=tuple(backends),
        where=where,
        rows=ordered,
        summary=summarize_backends(ordered, backends, shift),
        disagreement=qp_disagreement(ordered),
        shift_us=shift,
        interrupted=interrupted,
    )
