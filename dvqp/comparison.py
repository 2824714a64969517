"""Run scenes with several backends on the same commands and gather comparable figures.

Each scene is loaded once per worker and run with every backend in turn, so the ratio of a
backend's step time to ``pinv``'s compares runs made in the same process, one after the
other. :func:`compare` runs scenes in parallel processes when ``jobs > 1`` (timings are then
noisier: the processes share the machine).
"""

from __future__ import annotations

import os
import platform
import signal
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from typing import TYPE_CHECKING, Any

import numpy as np

from dvqp import load_scene, plan
from dvqp.errors import DvqpError
from dvqp.geometry import proximity
from dvqp.kinematics import KinematicState
from dvqp.limits import self_distance
from dvqp.planning import check_run, final_errors, worst_sample_excess
from dvqp.resolution.registry import PINV

if TYPE_CHECKING:
    from dvqp import Scene, Trajectory

FIELDS = (
    "scene", "file", "backend", "success", "steps", "failures", "relaxed", "braking", "substepped",
    "median_step_us", "p95_step_us", "median_solver_us", "median_rest_us", "median_iterations",
    "ratio_to_pinv", "max_task_error", "min_clearance",
    "closest", "min_probe_clearance", "min_tilt", "min_self_distance", "closest_pair",
    "max_joint_acceleration", "max_limit_excess", "worst_limit",
    "max_joint_limit_violation", "max_velocity_limit_violation", "final_tracking_error", "error",
)  # fmt: skip
"""Keys of a result row, in table / CSV order."""

Row = dict[str, Any]


def _finite(value: float) -> float | None:
    """``value`` as a float, or None if it is NaN or infinite (JSON has no NaN)."""
    v = float(value)
    return v if np.isfinite(v) else None


def summarize(scene: Scene, traj: Trajectory) -> Row:
    """The figures of one run.

    Parameters
    ----------
    scene
        The scene that was run.
    traj
        Its trajectory, from :func:`dvqp.plan`.

    Returns
    -------
    dict
        ``success``: the run can be sent to the arm — no step failed, every saved sample
        keeps every limit to its tolerance, and a path's end was reached
        (:func:`dvqp.planning.check_run`); ``error`` says why not. ``steps``; ``failures``
        (steps not solved or that broke a limit even in substeps); ``relaxed`` (steps whose
        task gave way to a limit) and ``braking`` (steps where the limits conflicted among
        themselves and the arm slowed down toward rest); ``substepped`` (steps split to keep
        a limit); median and 95th-percentile full step time (µs), the medians of the solver
        call alone and of the rest of the step (µs) and of the solver's iterations; the largest
        task error
        ``‖J̄Q̇ − ẋ‖∞`` of the succeeded steps; the smallest clearance of any guarded part
        (m) and the part and obstacle that have it (``closest``); the probe's own smallest
        clearance (m); the smallest probe tilt from radial (rad); the smallest distance
        between non-adjacent links (m) and that pair (``closest_pair``); the largest joint
        acceleration (rad/s²); ``max_limit_excess`` of the worst limit (in its unit, see
        ``worst_limit``); the largest joint-limit violation (rad) of ``q`` and
        velocity-limit violation (rad/s) of ``Q̇``; the final tracking error (m) against the
        commanded motion; ``final_tool`` ``[l, z, h, α]``. Undefined figures are None.
    """
    ok = traj.success
    steps_us = traj.step_time * 1e6
    return {
        "scene": scene.name,
        "file": scene.source,
        "backend": traj.backend,
        "success": (why := run_error(scene, traj)) is None,
        "steps": traj.n_steps,
        "failures": int(np.sum(~ok)),
        "relaxed": int(np.sum(traj.status == "relaxed")),
        "braking": int(np.sum(traj.status == "braking")),
        "substepped": int(np.sum(traj.substeps > 1)) if traj.substeps.size else None,
        "median_step_us": _finite(np.median(steps_us)) if traj.n_steps else None,
        "p95_step_us": _finite(np.percentile(steps_us, 95)) if traj.n_steps else None,
        **_solver_figures(traj),
        "ratio_to_pinv": None,
        "max_task_error": _finite(np.max(traj.task_error[ok])) if np.any(ok) else None,
        **_clearances(scene, traj),
        **_limit_figures(scene, traj),
        "final_tracking_error": final_errors(traj)[0] if traj.tracking_error.size else None,
        "final_tool": [float(v) for v in traj.tool[-1]],
        "error": why,
    }


def _solver_figures(traj: Trajectory) -> Row:
    """Medians of the solver call alone (µs), of the rest of the step (µs) and of the solver's
    iterations (None where not reported)."""
    if not traj.n_steps or not traj.solver_time.size:
        return {"median_solver_us": None, "median_rest_us": None, "median_iterations": None}
    solver_us = traj.solver_time * 1e6
    counted = traj.iterations[traj.iterations >= 0]
    return {
        "median_solver_us": _finite(np.median(solver_us)),
        "median_rest_us": _finite(np.median(traj.step_time * 1e6 - solver_us)),
        "median_iterations": _finite(np.median(counted)) if counted.size else None,
    }


def _clearances(scene: Scene, traj: Trajectory) -> Row:
    """``min_clearance``, ``closest``, ``min_probe_clearance`` and ``min_tilt``."""
    closest = None
    if len(scene.obstacles) and np.isfinite(traj.min_clearance).any():
        k = int(np.argmin(traj.min_clearance))
        state = KinematicState.compute(scene.robot, traj.q[k], scene.pipe_radius)
        _, part, j = proximity(state, scene.obstacles).closest()
        closest = f"{part}/obstacle{j + 1}"
    return {
        "min_clearance": _finite(np.min(traj.min_clearance)),
        "closest": closest,
        "min_probe_clearance": _finite(np.min(traj.probe_clearance))
        if traj.probe_clearance.size
        else None,
        "min_tilt": _finite(np.min(traj.tilt)) if traj.tilt.size else None,
        **_self_distance(scene, traj),
        "max_joint_acceleration": _finite(np.abs(traj.qddot).max()) if traj.qddot.size else None,
    }


def _self_distance(scene: Scene, traj: Trajectory) -> Row:
    """``min_self_distance`` (m) and ``closest_pair`` (e.g. ``"link1/holder"``)."""
    if not traj.self_distance.size:
        return {"min_self_distance": None, "closest_pair": None}
    k = int(np.argmin(traj.self_distance))
    _, pair = self_distance(KinematicState.compute(scene.robot, traj.q[k], scene.pipe_radius))
    return {"min_self_distance": _finite(traj.self_distance[k]), "closest_pair": pair or None}


def _limit_figures(scene: Scene, traj: Trajectory) -> Row:
    """The worst exact limit excess, and the joint position and velocity violations."""
    robot = scene.robot
    q_out = np.maximum(robot.q_min - traj.q, traj.q - robot.q_max)
    qd_out = np.abs(traj.qdot) - robot.qd_max
    worst = worst_sample_excess(scene, traj)
    if worst is not None and worst[1].value <= 0.0:  # kept, or a limit not in the scene
        worst = None
    return {
        "max_limit_excess": float(worst[1].value) if worst is not None else 0.0,
        "worst_limit": (
            f"{worst[1].label} {worst[1].quantity} ({worst[1].unit})" if worst is not None else None
        ),
        "max_joint_limit_violation": float(max(0.0, np.max(q_out))),
        "max_velocity_limit_violation": float(max(0.0, np.max(qd_out, initial=0.0))),
    }


def run_error(scene: Scene, traj: Trajectory) -> str | None:
    """Why a planned run failed (the message of :func:`dvqp.planning.check_run`), or None."""
    try:
        check_run(scene, traj)
    except DvqpError as exc:
        return str(exc)
    return None


def run_scene(
    path: str, backends: Sequence[str], progress: Callable[[str], None] | None = None
) -> list[Row]:
    """Load a scene and run it with every backend; the rows in ``backends`` order.

    A run that raises a :class:`~dvqp.errors.DvqpError` (a singular configuration, a solver
    that gave up) gives a row with ``success`` False and the message in ``error``.
    ``progress(backend)`` is called after each run.
    """
    scene = load_scene(path)
    rows = []
    for backend in backends:
        try:
            row = summarize(scene, plan(scene, backend))
        except DvqpError as exc:
            row = _error_row(scene, backend, exc)
        rows.append(row)
        if progress is not None:
            progress(backend)
    _add_ratios(rows)
    return rows


def _error_row(scene: Scene, backend: str, exc: DvqpError) -> Row:
    """The row of a run that raised: every figure None, ``success`` False, ``error`` set."""
    row: Row = {key: None for key in (*FIELDS, "final_tool")}
    row.update(scene=scene.name, file=scene.source, backend=backend, success=False)
    row["error"] = str(exc)
    return row


def _add_ratios(rows: Sequence[Row]) -> None:
    """Set ``ratio_to_pinv``: median step time over ``pinv``'s among ``rows`` (one scene)."""
    base = next((r["median_step_us"] for r in rows if r["backend"] == PINV), None)
    for row in rows:
        if base and row["median_step_us"] is not None:
            row["ratio_to_pinv"] = row["median_step_us"] / base


def compare(
    paths: Sequence[str],
    backends: Sequence[str],
    jobs: int = 1,
    progress: Callable[[int, int, str], None] | None = None,
) -> list[Row]:
    """Run every scene with every backend; rows grouped by scene in ``paths`` order.

    Parameters
    ----------
    paths
        Scene files (already validated by the caller, or errors surface here).
    backends
        Resolver names (checked by the caller with
        :func:`dvqp.resolution.registry.check_name`; an unknown one gives failed rows).
    jobs
        Worker processes (one scene per task); 1 runs in this process.
    progress
        Called as ``progress(done, total, label)``, counting runs (scene × backend).
    """
    total, done = len(paths) * len(backends), 0
    results: dict[str, list[Row]] = {}

    def tick(count: int, label: str) -> None:
        nonlocal done
        done += count
        if progress is not None:
            progress(done, total, label)

    if jobs <= 1 or len(paths) <= 1:
        for path in paths:
            results[path] = run_scene(path, backends, lambda b, p=path: tick(1, f"{p} {b}"))
    else:
        with ProcessPoolExecutor(max_workers=jobs, initializer=quiet_worker) as pool:
            futures = {pool.submit(run_scene, path, list(backends)): path for path in paths}
            for future in as_completed(futures):
                results[futures[future]] = future.result()
                tick(len(backends), futures[future])
    return [row for path in paths for row in results[path]]


def machine() -> dict[str, Any]:
    """Platform, processor, CPU count and Python version of this machine."""
    return {
        "platform": platform.platform(),
        "processor": platform.processor() or platform.machine(),
        "cpu_count": os.cpu_count(),
        "python": platform.python_version(),
    }


def quiet_worker() -> None:
    """Make Ctrl-C end this worker process at once, silently (exit code 130).

    For ``ProcessPoolExecutor(initializer=quiet_worker)``: workers that are not forked from
    inside :func:`interruptible` (the ``spawn`` and ``forkserver`` start methods) then stop as
    forked ones do, instead of each printing a traceback.
    """
    signal.signal(signal.SIGINT, lambda signum, frame: os._exit(130))
