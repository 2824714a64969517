"""Run scenes with several backends on the same commands; their rows as a table or CSV.

A scene's backends run one after the other in one process (so ``ratio_to_pinv`` is fair), scenes
in parallel when ``jobs > 1`` (noisier timings). The row helpers serve ``dvqp bench``.
"""

from __future__ import annotations

import os
import platform
import signal
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from dvqp.errors import DvqpError
from dvqp.geometry import proximity
from dvqp.kinematics import KinematicState
from dvqp.limits import lowest_link, self_distance, start_broken_lines
from dvqp.resolution.registry import PINV
from dvqp.run.levels import level_figures
from dvqp.run.planning import check_run, path_figures, plan
from dvqp.run.sample_checks import final_errors, tracking, worst_sample_excess
from dvqp.run.table_text import csv_text
from dvqp.scenes.scene import load_scene
from solvers.accuracy import METRICS

if TYPE_CHECKING:
    from dvqp.motion.trajectory import Trajectory
    from dvqp.scenes.scene import Scene

FIELDS = (
    "scene",
    "file",
    "backend",
    "settings",
    "success",
    "tracked",
    "steps",
    "failures",
    "slowed",
    "relaxed",
    "braking",
    "substepped",
    "nominal_duration",
    "path_duration",
    "max_deviation",
    "median_step_us",
    "p95_step_us",
    "median_solver_us",
    "median_rest_us",
    "median_iterations",
    "refused_calls",
    "refusals",
    "qp_solves",
    "unanswered_solves",
    "primal_residual",
    "dual_residual",
    "duality_gap",
    "ratio_to_pinv",
    "max_task_error",
    "max_tracking_error",
    "max_heading_error",
    "min_clearance",
    "closest",
    "min_probe_clearance",
    "min_tilt",
    "min_self_distance",
    "closest_pair",
    "min_link_height",
    "lowest_link",
    "max_joint_acceleration",
    "max_limit_excess",
    "worst_limit",
    "start_broken",
    "max_joint_limit_violation",
    "max_velocity_limit_violation",
    "final_tracking_error",
    "final_joint_speed",
    "braking_time",
    "levels_gave_way",
    "levels_least_squares",
    "level_detail",
    "error",
)
"""Keys of a result row, in table / CSV order."""

Row = dict[str, Any]


def _finite(value: float) -> float | None:
    """``value`` as a float, or None if NaN or infinite (JSON has no NaN)."""
    return v if np.isfinite(v := float(value)) else None


def _least(values: NDArray[np.float64]) -> float | None:
    """The smallest of ``values`` if any, and if it is finite; else None."""
    return _finite(np.min(values)) if values.size else None


def summarize(scene: Scene, traj: Trajectory, settings: str = "default") -> Row:
    """The figures of one run of ``scene`` (``traj`` from :func:`dvqp.plan` under the
    ``settings`` tier, :mod:`solvers.tiers`), as a dict:

    ``success``: the run can be sent to the arm (:func:`dvqp.run.planning.check_run`); ``error``
    says why not. ``tracked``: the tool followed the commanded motion within the scene's
    tolerance at every sample, with ``max_tracking_error`` (m) and ``max_heading_error`` (rad)
    (a safe run, ``success``, may still fall behind or leave the path where a backend's answers
    were refused). ``steps``; ``failures`` (steps not solved or that broke a limit even in
    substeps); ``slowed`` (a time-scaled path's progress slowed to keep the limits; a path's
    ``nominal_duration``, ``path_duration`` and ``max_deviation`` are those of
    :func:`dvqp.run.planning.path_figures`); ``relaxed`` (the task gave way to a limit) and
    ``braking`` (the limits conflicted: the arm slowed toward rest); ``substepped``;
    median and 95th-percentile full step time (µs), the medians of the solver call alone and
    of the rest of the step (µs) and of the solver's iterations; the backend calls refused (no
    accepted answer: the step relaxed or braked) and by kind (``refusals``); the steps' QP
    answers counted (``qp_solves``, :attr:`dvqp.resolution.qp.QPSolver.accuracy`), of those
    ``unanswered_solves``, and qpbenchmark's shifted geometric means of their primal and dual
    residuals and duality gaps (an unanswered one counted at its check's tolerance;
    :mod:`solvers.accuracy`; None for the baseline); the largest task error
    ``‖J̄Q̇ − ẋ‖∞`` of the succeeded steps; the smallest clearance of any guarded part (m) and
    the part and obstacle that have it (``closest``); the probe's own smallest clearance (m);
    the smallest probe tilt from radial (rad); the smallest distance between non-adjacent
    links (m) and that pair (``closest_pair``); the lowest height of the body and carriage
    links' chords (m) and that link (``lowest_link``); the largest joint acceleration
    (rad/s²); ``max_limit_excess`` of the worst limit past its true bound (in its unit, see
    ``worst_limit``), also of a limit the start broke, which ``start_broken`` names (a line
    per limit of :func:`dvqp.limits.start_broken_lines`, ``"; "``-joined; None if none); the
    largest joint-limit violation (rad) of ``q`` and velocity-limit violation (rad/s) of
    ``Q̇``; the final tracking error (m); ``final_joint_speed``, the largest ``|Q̇|`` of the
    last step that succeeded (rad/s; 0: at rest), ``braking_time`` (s; None: not stopped) and
    ``final_tool`` ``[l, z, h, α]``. A run with hard tasks at more than one priority has
    ``levels_gave_way`` (each level's relaxed steps that did not meet it exactly, ``"0/161"``,
    priority order), ``levels_least_squares`` (each level's steps that met it in least squares,
    not relaxed) and ``level_detail`` (each level kept exactly or given way, and its worst error in
    mm and rad, :func:`dvqp.run.levels.level_figures`); None with one level. Undefined figures
    are None.
    """
    ok = traj.success
    steps_us = traj.step_time * 1e6
    return {
        "scene": scene.name,
        "file": scene.source,
        "backend": traj.backend,
        "settings": settings,
        "success": (why := run_error(scene, traj)) is None,
        "steps": traj.n_steps,
        "failures": int(np.sum(~ok)),
        "slowed": int(np.sum(traj.status == "slowed")),
        "relaxed": int(np.sum(traj.status == "relaxed")),
        "braking": int(np.sum(traj.status == "braking")),
        **path_figures(scene, traj),
        "substepped": int(np.sum(traj.substeps > 1)) if traj.substeps.size else None,
        "median_step_us": _finite(np.median(steps_us)) if traj.n_steps else None,
        "p95_step_us": _finite(np.percentile(steps_us, 95)) if traj.n_steps else None,
        **_solver_figures(traj),
        "refused_calls": sum(traj.refusals.values()),
        "refusals": traj.refused or None,
        **_accuracy(traj),
        "ratio_to_pinv": None,
        "max_task_error": _finite(np.max(traj.task_error[ok])) if np.any(ok) else None,
        **_tracking(scene, traj),
        **_clearances(scene, traj),
        **_limit_figures(scene, traj),
        "final_tracking_error": final_errors(traj)[0] if traj.tracking_error.size else None,
        "final_joint_speed": final_joint_speed(traj),
        "braking_time": traj.braking_time,
        "final_tool": [float(v) for v in traj.tool[-1]],
        **_levels(traj),
        "error": why,
    }


def _levels(traj: Trajectory) -> Row:
    """``levels_gave_way`` and ``level_detail`` of a run with more than one level (else
    None)."""
    levels = level_figures(traj)
    if len(levels) < 2:
        return {"levels_gave_way": None, "levels_least_squares": None, "level_detail": None}
    return {
        "levels_gave_way": "/".join(str(level.gave_way) for level in levels),
        "levels_least_squares": "/".join(str(level.least_squares) for level in levels),
        "level_detail": "; ".join(
            f"level {k} ({level.name}) {level.words()}" for k, level in enumerate(levels, 1)
        ),
    }


def _tracking(scene: Scene, traj: Trajectory) -> Row:
    """``tracked`` (the tool within the scene's tolerance of the commanded motion at every
    sample, :func:`~dvqp.run.sample_checks.tracking`), ``max_tracking_error`` (m) and
    ``max_heading_error`` (rad); None without a recorded tracking error."""
    found = tracking(scene, traj)
    if found is None:
        return {"tracked": None, "max_tracking_error": None, "max_heading_error": None}
    tracked, position, heading = found
    return {
        "tracked": tracked,
        "max_tracking_error": _finite(position),
        "max_heading_error": _finite(heading),
    }


def final_joint_speed(traj: Trajectory) -> float:
    """The largest ``|Q̇|`` of the run's last step that succeeded, rad/s (0 if none did)."""
    moved = np.flatnonzero(traj.success)
    return float(np.abs(traj.qdot[moved[-1]]).max(initial=0.0)) if moved.size else 0.0


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


def _accuracy(traj: Trajectory) -> Row:
    """The steps' QP answers' count and accuracy (:attr:`Trajectory.accuracy`; None: baseline)."""
    a = traj.accuracy
    solves = int(a["solves"]) if "solves" in a else None
    return {
        "qp_solves": solves,
        "unanswered_solves": int(a["unanswered"]) if solves is not None else None,
        **{name: _finite(a[name]) if name in a else None for name in METRICS},
    }


def _clearances(scene: Scene, traj: Trajectory) -> Row:
    """Clearances, self distance, lowest link chord (and where), tilt, largest acceleration."""
    closest = None

    def at(values: NDArray[np.float64]) -> KinematicState:  # the state of the lowest sample
        return KinematicState.compute(scene.robot, traj.q[np.argmin(values)], scene.pipe_radius)

    if len(scene.obstacles) and np.isfinite(traj.min_clearance).any():
        near = proximity(at(traj.min_clearance), scene.obstacles)
        _, part, j = near.closest()
        side = near.closest_side()
        closest = f"{part}/{scene.obstacles.labels[j]}" + (f", {side}" if side else "")
    pair = self_distance(at(traj.self_distance))[1] if traj.self_distance.size else None
    link = lowest_link(at(traj.link_height))[1] if traj.link_height.size else None
    return {
        "min_clearance": _finite(np.min(traj.min_clearance)),
        "closest": closest,
        "min_probe_clearance": _least(traj.probe_clearance),
        "min_tilt": _least(traj.tilt),
        "min_self_distance": _least(traj.self_distance),
        "closest_pair": pair or None,
        "min_link_height": _least(traj.link_height),
        "lowest_link": link or None,
        "max_joint_acceleration": _finite(np.abs(traj.qddot).max()) if traj.qddot.size else None,
    }


def _limit_figures(scene: Scene, traj: Trajectory) -> Row:
    """The worst exact limit excess, and the joint position and velocity violations."""
    q_out = np.maximum(scene.robot.q_min - traj.q, traj.q - scene.robot.q_max)
    qd_out = np.abs(traj.qdot) - scene.robot.qd_max
    worst = worst_sample_excess(scene, traj)
    found = [b.excess for b in traj.start_broken]  # past their true bounds, not their starts'
    if worst is not None and not worst[1].value <= 0.0:  # else kept
        found.append(worst[1])
    excess = max(found, key=lambda e: e.ratio) if found else None
    return {
        "max_limit_excess": float(excess.value) if excess else 0.0,
        "worst_limit": f"{excess.label} {excess.quantity} ({excess.unit})" if excess else None,
        "start_broken": "; ".join(start_broken_lines(traj.start_broken)) or None,
        "max_joint_limit_violation": float(max(0.0, np.max(q_out))),
        "max_velocity_limit_violation": float(max(0.0, np.max(qd_out, initial=0.0))),
    }


def run_error(scene: Scene, traj: Trajectory) -> str | None:
    """Why a planned run failed (:func:`dvqp.run.planning.check_run`'s message), or None."""
    try:
        check_run(scene, traj)
    except DvqpError as exc:
        return str(exc)
    return None


def run_scene(
    path: str,
    backends: Sequence[str],
    progress: Callable[[str], None] | None = None,
    options: dict[str, dict[str, Any]] | None = None,
    tier: str = "default",
    timing: str | None = None,
) -> list[Row]:
    """Load a scene and run it with every backend (``options``: settings by backend, over the
    ``tier``'s, :mod:`solvers.tiers`; ``timing``: a path scene's, :func:`dvqp.plan`); the rows
    in ``backends`` order. A run that raises a :class:`~dvqp.errors.DvqpError` gives an
    :func:`error_row`. ``progress(backend)`` is called after each run.
    """
    scene, given = load_scene(path), options or {}
    rows = []
    for backend in backends:
        try:
            traj = plan(
                scene,
                backend,
                options=given.get(backend),
                tier=tier,
                timing=timing if scene.path is not None else None,
            )
            rows.append(summarize(scene, traj, tier))
        except DvqpError as exc:
            rows.append(error_row(scene, backend, exc))
        if progress is not None:
            progress(backend)
    add_ratios(rows)
    return rows


def error_row(scene: Scene, backend: str, exc: Exception, extra: Sequence[str] = ()) -> Row:
    """A run that raised: ``error`` says why, every other figure (:data:`FIELDS`, ``extra``,
    ``final_tool``) None and ``success`` False."""
    row: Row = dict.fromkeys((*FIELDS, *extra, "final_tool"))
    row.update(scene=scene.name, file=scene.source, backend=backend, success=False, error=str(exc))
    return row


def add_ratios(rows: Sequence[Row]) -> None:
    """Set ``ratio_to_pinv`` of ``rows`` (one scene's): median step time over ``pinv``'s."""
    base = next((r["median_step_us"] for r in rows if r["backend"] == PINV), None)
    for row in rows:
        if base and row.get("median_step_us") is not None:
            row["ratio_to_pinv"] = row["median_step_us"] / base


def compare(
    paths: Sequence[str],
    backends: Sequence[str],
    jobs: int = 1,
    progress: Callable[[int, int, str], None] | None = None,
    options: dict[str, dict[str, Any]] | None = None,
    tier: str = "default",
    timing: str | None = None,
) -> list[Row]:
    """Run every scene with every backend; rows grouped by scene in ``paths`` order.

    The scene files and backend names are checked by the caller (else scene errors surface
    here; an unknown backend gives failed rows). ``jobs`` worker processes run one scene each
    (1: all in this process). ``progress(done, total, label)`` counts runs (scene × backend);
    ``options``: backends' settings, over each scene's own, over the settings ``tier``'s;
    ``timing``: that of every path scene (default: each scene's own).
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
            results[path] = run_scene(
                path, backends, lambda b, p=path: tick(1, f"{p} {b}"), options, tier, timing
            )
    else:
        with ProcessPoolExecutor(max_workers=jobs, initializer=quiet_worker) as pool:
            futures = {
                pool.submit(run_scene, path, list(backends), None, options, tier, timing): path
                for path in paths
            }
            for future in as_completed(futures):
                results[futures[future]] = future.result()
                tick(len(backends), futures[future])
    return [row for path in paths for row in results[path]]


def rows_to_csv(rows: Sequence[Row], fields: Sequence[str] = FIELDS) -> str:
    """The rows as CSV text: a header of ``fields`` (default :data:`FIELDS`), one line a row."""
    return csv_text(rows, fields)


def machine() -> dict[str, Any]:
    """Platform, processor, CPU count and Python version of this machine."""
    processor = platform.processor() or platform.machine()
    return {
        "platform": platform.platform(),
        "processor": processor,
        "cpu_count": os.cpu_count(),
        "python": platform.python_version(),
    }


def quiet_worker() -> None:
    """Ctrl-C ends this worker at once, silently (exit 130), as in a forked one (initializer)."""
    signal.signal(signal.SIGINT, lambda signum, frame: os._exit(130))
