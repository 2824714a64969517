"""A run's common steps in one compiled loop; Python takes every other step.

Most steps of a run are common: the command of the schedule, the strict QP's warm attempt
accepted (or the baseline's step), the state reached regular and within every verified limit,
its largest joint motion below :data:`~dvqp.step.JOINT_STRIDE` (no interior point to check).
:func:`follow` runs such steps one after another in compiled code, each exactly as
:func:`dvqp.step.advance` would (the same compiled calls, :func:`~dvqp.step.stages.
resolve_move` and :func:`~dvqp.motion.schedule.command_into`), and writes each into the
recorder's arrays. At the first step that is not common (a refused attempt, a singular
state, a broken limit, a large step) it returns with that step's compiled call made, and
Python finishes the step from its values (:class:`~dvqp.step.engine.Made`): judged, retried,
slowed, relaxed, split or failed as :func:`~dvqp.step.advance` does it. A run's trajectory is
the same, bit for bit, with the loop or without it; only the times differ (the loop's are read
from the same clock, ``time.perf_counter``'s, in compiled code).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from dvqp.motion.recorder import TrajectoryRecorder
from dvqp.motion.schedule import Schedule, ScheduleArrays, command_into
from dvqp.step import JOINT_STRIDE, Stepper
from dvqp.step.engine import Made
from dvqp.step.stages import MOVED, NOT_ATTEMPTED, resolve_move, resolve_move_baseline
from dvqp.workspace import as_struct
from solvers.accuracy import add_kernel_metrics
from solvers.clock import now
from solvers.daqp_c import H_CLOCK
from solvers.jit import njit

Array = NDArray[np.float64]
Index = NDArray[np.int64]

MADE = 15
"""The values of a step's compiled call (:func:`~dvqp.step.stages.resolve_move`'s)."""
STOPPED, HANDED = 0.0, 1.0
"""How :func:`follow` returns: it stopped before a step (the schedule's end, ``until``), or
it hands a step it made but cannot take as it is to Python."""


@dataclass(frozen=True)
class FollowArrays:
    """What :func:`follow` reads and writes besides the step's own arrays.

    ``schedule`` the run's commands; the recorder's per-step arrays (N steps, n joints, L
    levels: ``solve_time``, ``solver_time``, ``step_time``, ``task_error`` (N,) s and task
    units per s, ``level_error`` (N, L), ``iterations`` (N,), ``substeps`` (N,), ``success``
    (N,), ``qdot`` (N, n) rad/s); ``progress`` (B + 1,): the schedule's progress ``u`` at each
    sample; the strict problem's ``feedforward`` (m,; size 0 for the baseline) and the rows
    and command components it paces (:meth:`dvqp.step.Stepper.pace`); where the velocity is
    observed (``observed`` (n,), size 0: nowhere); the accuracy tally's ``log_sums`` (3,) and
    ``solves`` (1,) counted here; ``start`` (n,) the configuration the last step started
    from and ``made`` (15,) its compiled call's values; ``nominal`` (4,) scratch; ``verify``
    (check every limit) and ``stride`` (rad, the largest joint motion of a step checked at
    its end only)."""

    schedule: ScheduleArrays
    solve_time: Array
    solver_time: Array
    step_time: Array
    task_error: Array
    level_error: Array
    iterations: Index
    substeps: Index
    success: NDArray[np.bool_]
    qdot: Array
    progress: Array
    feedforward: Array
    paced_rows: Index
    paced_components: Index
    observed: Array
    log_sums: Array
    solves: Index
    start: Array
    made: Array
    nominal: Array
    verify: bool
    stride: float


class Followed(NamedTuple):
    """Where :meth:`Follower.run` left the run: the next step ``k``, the progress ``u``, the
    time the next step starts (``time.perf_counter``'s s) and the step ``k`` it hands over
    made (None: it stopped before step ``k``)."""

    k: int
    u: float
    started: float
    made: Made | None


class Follower:
    """Runs a run's common steps in compiled code (:func:`follow`).

    Parameters
    ----------
    stepper, record, schedule
        The run's step, its recorder and its commands.
    verify
        Every limit is checked (as :func:`~dvqp.step.advance`'s ``verify``).
    """

    def __init__(
        self, stepper: Stepper, record: TrajectoryRecorder, schedule: Schedule, verify: bool
    ) -> None:
        self.stepper, self.record, self.schedule, self.verify = stepper, record, schedule, verify
        self.progress = np.zeros(schedule.budget + 1)
        """The schedule's progress ``u`` at each sample, (B + 1,) (written by the loop and by
        :meth:`took` for the steps Python takes)."""
        self._packed: tuple[FollowArrays, Any] | None = None  # the arrays and their struct

    def _struct(self) -> tuple[FollowArrays, Any]:
        """The loop's arrays and their struct (packed again when the recorder has grown)."""
        a = self.record.arrays
        if self._packed is not None and self._packed[0].qdot is a["qdot"]:
            return self._packed
        stepper = self.stepper
        solver = stepper.solver
        rows, components = stepper.paced
        if solver is None:  # the baseline is not paced (Stepper.pace)
            rows, components = rows[:0], components[:0]
        observed = stepper.observed
        arrays = FollowArrays(
            self.schedule.arrays,
            *(a[name] for name in ("solve_time", "solver_time", "step_time", "task_error")),
            a["level_error"],
            a["iterations"],
            a["substeps"],
            a["success"],
            a["qdot"],
            self.progress,
            np.zeros(0) if solver is None else solver.feedforward,
            rows.astype(np.int64),
            components.astype(np.int64),
            np.zeros(0) if observed is None else observed,
            np.zeros(3),
            np.zeros(1, np.int64),
            np.zeros(stepper.robot.n),
            np.zeros(MADE),
            np.zeros(4),
            bool(self.verify),
            float(JOINT_STRIDE),
        )
        self._packed = (arrays, as_struct(arrays))
        return self._packed

    def compile(self) -> None:
        """Compile (or load) the loop this run takes, without taking a step."""
        self.run(0, 0.0, 0.0, until=0)

    def run(self, k: int, u: float, started: float, until: int | None = None) -> Followed:
        """The common steps from step ``k`` at progress ``u`` (the step starting at
        ``started``), until the schedule's end, its budget, the recorder's room or ``until``
        steps; each recorded (status ``"optimal"``) and counted. The step after them, made,
        is handed over when it is not common."""
        stepper, record, schedule = self.stepper, self.record, self.schedule
        fused = stepper.fused()
        if fused is None:
            return Followed(k, u, started, None)
        handle, qp = fused
        room = min(schedule.budget, record.arrays["qdot"].shape[0])
        stop = room if until is None else min(until, room)
        arrays, f = self._struct()
        tally = None if stepper.solver is None else stepper.solver.accuracy
        if tally is not None:
            arrays.log_sums[:] = tally.log_sums
            arrays.solves[0] = 0
        kernel = follow if qp else follow_baseline
        out = kernel(stepper.struct, handle, f, k, u, started, stop)
        reached = int(out[1])
        if tally is not None:
            tally.log_sums = [float(v) for v in arrays.log_sums]
            tally.solves += int(arrays.solves[0])
        if reached > k:
            record.status[k:reached] = "optimal"
            record.steps = reached
        if out[0] != HANDED:
            return Followed(reached, float(out[2]), float(out[3]), None)
        made = Made(arrays.start.copy(), float(out[4]), tuple(arrays.made.tolist()))
        return Followed(reached, float(out[2]), float(out[3]), made)


@njit(inline="always")
def _loop(resolve, s, handle, clock, f, k, u, started, until, counted):  # type: ignore[no-untyped-def]
    """The loop of :func:`follow` and :func:`follow_baseline` (``resolve`` the step's
    compiled call, 15 values; ``counted``: its values carry a solve to count)."""
    a = f.schedule
    while k < until and not u >= a.n - 1e-9:
        for i in range(f.start.shape[0]):
            f.start[i] = s.state.q[i]
        begun = now(clock)
        span = command_into(a, u, s.state.tool, s.command, f.nominal)
        s.dt[0] = a.dt
        if a.scaled:  # pace: the tool rows' nominal motion
            for i in range(f.feedforward.shape[0]):
                f.feedforward[i] = 0.0
            for j in range(f.paced_rows.shape[0]):
                f.feedforward[f.paced_rows[j]] = f.nominal[f.paced_components[j]]
        s.record.index[0] = k + 1
        out = resolve(s, handle)
        if (
            out[0] != MOVED
            or out[1] != -1.0
            or (f.verify and (not s.checks.excess[1] <= 1.0 or s.motion[1] > f.stride))
        ):
            for i in range(MADE):
                f.made[i] = out[i]
            return (HANDED, float(k), u, started, begun)
        ended = now(clock)
        x = s.x
        for i in range(x.shape[0]):
            f.qdot[k, i] = x[i]
        for i in range(f.observed.shape[0]):
            f.observed[i] = x[i]
        f.success[k] = True
        f.substeps[k] = 1
        f.task_error[k] = s.motion[0]
        levels = s.tasks.level_error
        for i in range(f.level_error.shape[1]):
            f.level_error[k, i] = levels[i] if levels.shape[0] > 1 else s.motion[0]
        spent = ended - begun - out[2]
        f.solve_time[k] = spent
        if counted:
            f.iterations[k] = int(out[5])
            f.solver_time[k] = out[6]
            add_kernel_metrics(f.log_sums, out[7:15])
            f.solves[0] += 1
        else:
            f.iterations[k] = -1
            f.solver_time[k] = spent
        f.step_time[k] = ended - started
        started = ended
        u += span
        k += 1
        f.progress[k] = u
    return (STOPPED, float(k), u, started, 0.0)


@njit(inline="always")
def _baseline(s, clock):  # type: ignore[no-untyped-def]
    """The baseline's step and move (:func:`~dvqp.step.stages.resolve_move_baseline`), its
    values padded to :func:`~dvqp.step.stages.resolve_move`'s 15."""
    status, singular, moving = resolve_move_baseline(s, clock)
    return (status, singular, moving, *NOT_ATTEMPTED)


@njit
def follow(s, w, f, k, u, started, until):  # type: ignore[no-untyped-def]
    """A QP run's common steps from step ``k`` at progress ``u`` (the step starting at
    ``started``, s of ``time.perf_counter``'s clock), on the step's struct ``s``, the strict
    backend's packed attempt ``w`` (:meth:`~dvqp.resolution.qp.QPSolver.fused_attempt`) and
    the loop's arrays ``f`` (:class:`FollowArrays`), up to step ``until`` (excluded).

    Returns
    -------
    tuple of 5 floats
        ``(how, k, u, started, begun)``: :data:`STOPPED` before step ``k``, or
        :data:`HANDED` with step ``k`` made, its resolution begun at ``begun``, its compiled
        call's values (:func:`~dvqp.step.stages.resolve_move`'s) in ``f.made``.
    """
    return _loop(resolve_move, s, w, w.call.handles[H_CLOCK], f, k, u, started, until, True)


@njit
def follow_baseline(s, clock, f, k, u, started, until):  # type: ignore[no-untyped-def]
    """:func:`follow` for the baseline (``clock``: :func:`solvers.clock.address`); a handed
    step's values are :func:`~dvqp.step.stages.resolve_move_baseline`'s, then NaN."""
    return _loop(_baseline, s, clock, clock, f, k, u, started, until, False)
