"""Run one generated scene with every backend: the unit of work a worker gets.

:func:`run_job` takes the scene's text (not a file), so a local process, a thread of a Dask
worker or a remote machine run exactly the same scene.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from dvqp.errors import DvqpError
from dvqp.motion import Trajectory
from dvqp.run.comparison import Row, add_ratios, error_row, summarize
from dvqp.run.planning import plan
from dvqp.scenes import Scene, loads

EXTRA_FIELDS = (
    "mode",
    "dt",
    "obstacles",
    "mean_step_us",
    "mean_solve_us",
    "median_solve_us",
    "total_step_s",
    "capped_calls",
)
"""Keys a bench row adds to :data:`dvqp.run.comparison.FIELDS`, after ``index`` (its first key)."""

WORKER_LOST = "worker lost"
"""The ``error`` of a run whose worker died (twice) before answering."""
LOST = (WORKER_LOST, "timed out")
"""How the ``error`` of a lost run begins: its worker died, or gave no answer in time."""


@dataclass(frozen=True)
class Job:
    """One scene to run: its ``index`` in the suite, its ``name`` (it is loaded as
    ``<name>.toml``), the scene file's ``text`` and the ``backends``, run in this order, with
    ``options`` (settings by backend, ``--solver-option``) over the settings ``tier``'s."""

    index: int
    name: str
    text: str
    backends: tuple[str, ...]
    options: dict[str, dict[str, Any]] = field(default_factory=dict)
    tier: str = "default"


def run_job(job: Job, on_run: Callable[[str], None] | None = None) -> list[Row]:
    """Load the scene and run it with every backend; one row per backend, in order.

    The rows are those of :func:`dvqp.run.comparison.summarize` with ``ratio_to_pinv`` and
    :data:`EXTRA_FIELDS`; a run that raises a :class:`~dvqp.errors.DvqpError` gives a
    :func:`dvqp.run.comparison.error_row`. ``on_run(backend)`` is called after each run.
    """
    scene = loads(job.text, f"{job.name}.toml")
    rows = []
    for backend in job.backends:
        try:
            traj = plan(scene, backend, options=job.options.get(backend), tier=job.tier)
        except DvqpError as exc:
            row = error_row(scene, backend, exc, EXTRA_FIELDS)
        else:
            row = _figures(scene, traj, job.tier)
        rows.append(_with_scene(job, scene, row))
        if on_run is not None:
            on_run(backend)
    add_ratios(rows)
    return rows


def lost_rows(job: Job, reason: str = WORKER_LOST) -> list[Row]:
    """The rows of a scene whose worker gave no answer: one per backend, as a run that raised
    (:func:`dvqp.run.comparison.error_row`) with ``error`` ``reason`` (beginning as
    :data:`LOST`)."""
    scene = loads(job.text, f"{job.name}.toml")
    error = DvqpError(reason)
    return [_with_scene(job, scene, error_row(scene, b, error, EXTRA_FIELDS)) for b in job.backends]


def is_lost(row: Row) -> bool:
    """The row is of a lost run (:func:`lost_rows`)."""
    return str(row.get("error") or "").startswith(LOST)


def _with_scene(job: Job, scene: Scene, row: Row) -> Row:
    """``row`` with the scene's ``index`` first and its ``mode``, ``dt`` and obstacle shapes."""
    shapes = ",".join(o.kind for o in scene.obstacles)
    return {"index": job.index, **row, "mode": scene.mode, "dt": scene.dt, "obstacles": shapes}


def _figures(scene: Scene, traj: Trajectory, tier: str) -> Row:
    """:func:`dvqp.run.comparison.summarize`'s figures, then the bench's timings (µs, s)."""
    steps_us, solve_us = traj.step_time * 1e6, traj.solve_time * 1e6
    return {
        **summarize(scene, traj, tier),
        "mean_step_us": float(np.mean(steps_us)) if steps_us.size else None,
        "mean_solve_us": float(np.mean(solve_us)) if solve_us.size else None,
        "median_solve_us": float(np.median(solve_us)) if solve_us.size else None,
        "total_step_s": float(np.sum(traj.step_time)),
        "capped_calls": sum(traj.refusals.get(k, 0) for k in ("iteration limit", "time limit")),
    }
