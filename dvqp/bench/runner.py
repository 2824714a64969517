"""Run one generated scene with every backend: the unit of work a worker gets.

:func:`run_job` takes the scene's text (not a file), so a local process, a thread of a Dask
worker or a remote machine run exactly the same scene; it returns one row per backend, the
figures of :func:`dvqp.comparison.summarize` plus the bench's own.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from dvqp.comparison import FIELDS, summarize
from dvqp.errors import DvqpError
from dvqp.motion import Trajectory
from dvqp.planning import plan
from dvqp.resolution.registry import PINV
from dvqp.scenes import Scene, loads

Row = dict[str, Any]

EXTRA_FIELDS = (
    "index", "mode", "dt", "obstacles", "mean_step_us", "mean_solve_us", "median_solve_us",
    "total_step_s",
)  # fmt: skip
"""Keys a bench row adds to :data:`dvqp.comparison.FIELDS` (and ``final_tool``)."""


@dataclass(frozen=True)
class Job:
    """One scene to run with every backend.

    Attributes
    ----------
    index : int
        The scene's index in the suite.
    name : str
        Its name; it is loaded as ``<name>.toml``.
    text : str
        The scene file's text.
    backends : tuple of str
        Resolver names, run in this order.
    """

    index: int
    name: str
    text: str
    backends: tuple[str, ...]


def run_job(job: Job, on_run: Callable[[str], None] | None = None) -> list[Row]:
    """Load the scene and run it with every backend; one row per backend, in order.

    A run that raises a :class:`~dvqp.errors.DvqpError` (a singular configuration, a solver
    that gave up) gives a row with ``success`` False, its message in ``error`` and every
    figure None. ``on_run(backend)`` is called after each run.
    """
    scene = loads(job.text, f"{job.name}.toml")
    rows = []
    for backend in job.backends:
        try:
            traj = plan(scene, backend)
        except DvqpError as exc:
            rows.append(_error_row(job, scene, backend, exc))
        else:
            rows.append(_row(job, scene, traj))
        if on_run is not None:
            on_run(backend)
    _add_ratios(rows)
    return rows


def _row(job: Job, scene: Scene, traj: Trajectory) -> Row:
    """The figures of one run: :func:`dvqp.comparison.summarize`'s and the bench's."""
    row = summarize(scene, traj)
    steps_us, solve_us = traj.step_time * 1e6, traj.solve_time * 1e6
    row.update(
        mean_step_us=_mean(steps_us),
        mean_solve_us=_mean(solve_us),
        median_solve_us=float(np.median(solve_us)) if solve_us.size else None,
        total_step_s=float(np.sum(traj.step_time)),
    )
    return _with_scene(row, job, scene)


def _mean(values: np.ndarray) -> float | None:
    return float(np.mean(values)) if values.size else None


def _with_scene(row: Row, job: Job, scene: Scene) -> Row:
    """``row`` with the scene's index, mode, step and obstacle shapes."""
    shapes = ",".join(o.kind for o in scene.obstacles)
    return {"index": job.index, **row, "mode": scene.mode, "dt": scene.dt, "obstacles": shapes}


def _error_row(job: Job, scene: Scene, backend: str, exc: DvqpError) -> Row:
    """The row of a run that raised: every figure None, ``success`` False, ``error`` set."""
    row: Row = {key: None for key in (*FIELDS, *EXTRA_FIELDS, "final_tool")}
    row.update(scene=scene.name, file=scene.source, backend=backend, success=False)
    row["error"] = str(exc)
    return _with_scene(row, job, scene)


def _add_ratios(rows: list[Row]) -> None:
    """``ratio_to_pinv``: median step time over ``pinv``'s on the same scene, same process."""
    base = next((r["median_step_us"] for r in rows if r["backend"] == PINV), None)
    for row in rows:
        if base and row.get("median_step_us") is not None:
            row["ratio_to_pinv"] = row["median_step_us"] / base
