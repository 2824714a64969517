"""A run's common steps in one compiled loop; Python takes every other step.

Most steps of a run are common: the command of the schedule, the strict QP's warm attempt
accepted (or the baseline's step), the state reached regular and within every verified limit,
its largest joint motion below :data:`~dvqp.step.JOINT_STRIDE` (no interior point to check).
So is a step of a relaxed streak at fixed timing: the strict problem's cold attempt refused
(the backend restarts cold after a refusal), the relaxed problem's warm attempt accepted. A
cold attempt first tries, as a proof that its strict problem admits no answer
(:mod:`solvers.farkas`), the multipliers the loop held in the strict backend's workspace
(:func:`solvers.daqp_c.hold_multipliers`: the least violation's, the relaxed or the
time-scaled answer's), then DAQP's infeasibility direction of the last refusal it found:
proved, that refusal solves nothing. Python's steps hold none; either way the refusals are the
same.
:func:`follow` runs such steps one after another in compiled code, each exactly as
:func:`dvqp.step.advance` and :meth:`~dvqp.resolution.qp.QPSolver.solve` would (the same
compiled calls, :func:`~dvqp.step.stages.resolve_move`, :func:`~dvqp.motion.schedule.
command_into`, :func:`~dvqp.resolution.levels.load_columns`), and writes each into the
recorder's arrays, its accuracy and refusal counted. At the first step that is not common (a
refused warm attempt, a time-scaled run's refusal, a relaxed attempt refused, a singular
state, a broken limit, a large step) it returns with what it made of that step, and Python
finishes the step from those values (:class:`~dvqp.step.engine.Made`): judged, retried,
slowed, relaxed, split or failed as :func:`~dvqp.step.advance` does it. A run's trajectory is
the same, bit for bit, with the loop or without it; only the times differ (the loop's are read
from the same clock, ``time.perf_counter``'s, in compiled code).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from dvqp.motion.recorder import TrajectoryRecorder
from dvqp.motion.schedule import Schedule, ScheduleArrays, command_into
from dvqp.resolution.levels import load_columns
from dvqp.resolution.pinv import pinv_step
from dvqp.resolution.qp import load_scaled
from dvqp.resolution.ray import ray_constants
from dvqp.step import JOINT_STRIDE, Stepper
from dvqp.step.engine import Made
from dvqp.step.stages import (
    ATTEMPTED,
    CONCLUDE,
    MEASURE,
    MOVED,
    NOT_ATTEMPTED,
    evaluate,
    resolve_move,
    resolve_move_baseline,
)
from dvqp.workspace import as_struct
from solvers._kkt import MISFIT
from solvers.accuracy import add_kernel_metrics
from solvers.clock import now
from solvers.daqp_c import (
    ACCEPTED,
    CERTIFIED,
    H_CLOCK,
    RESTART,
    SOLVED,
    WARM,
    attempt,
    certified,
    hold_multipliers,
    proves,
    solve_dropped,
)
from solvers.jit import njit, ready

Array = NDArray[np.float64]
Index = NDArray[np.int64]

MADE = 15
"""The values of a step's compiled call (:func:`~dvqp.step.stages.resolve_move`'s)."""
ATTEMPT = 12
"""The values of a backend's attempt (:func:`solvers.daqp_c.solve_dropped`'s)."""
STOPPED, HANDED = 0.0, 1.0
"""How :func:`follow` returns: it stopped before a step (the schedule's end, ``until``), or
it hands a step it made but cannot take as it is to Python."""
BATCH = 1000
"""Most steps one call of the loop takes (some ms): Python then handles a pending signal
(Ctrl-C) and shows the progress before the next."""
OPTIMAL, RELAXED, SLOWED = 0, 1, 2
"""The kinds of step the loop takes (``FollowArrays.kinds``)."""
KINDS = ("optimal", "relaxed", "slowed")
"""Their statuses."""
COMPILE = "warm"
"""When a run may compile its loop (:func:`follow`, or :func:`follow_baseline`: 2-3 s
together with the calls only they make; cached on disk, later runs load it): ``"warm"``, when
the run's first step compiled nothing (its kernels were loaded from the cache, or compiled by
an earlier run of the process), so that the first run after installing compiles only what
its steps need and the next one compiles the loop; ``"always"``; or ``"never"``. A run whose
loop is neither in the cache nor compiled takes every step in Python: the same run, bit for
bit, only slower by some microseconds a step."""
LONG_RUN = 100_000
"""Steps of a run (its schedule's budget) from which ``"warm"`` compiles the loop even in a
run that compiled its step: the loop saves about 17-33 µs a step on the paper scene (pinv,
DAQP: ``benchmarks/floor.py``), about its 2-3 s of compile over such a run."""


@dataclass(frozen=True)
class FollowArrays:
    """What :func:`follow` reads and writes besides the step's own arrays.

    ``schedule`` the run's commands; the recorder's per-step arrays (N steps, n joints, L
    levels: ``solve_time``, ``solver_time``, ``step_time``, ``task_error`` (N,) s and task units
    per s, ``level_error`` (N, L), ``iterations`` (N,), ``substeps`` (N,), ``success`` (N,),
    ``qdot`` (N, n) rad/s); each step's ``kinds`` (N,: :data:`OPTIMAL`, :data:`RELAXED`,
    :data:`SLOWED`) and such a step's strict refusal, its exit ``flags`` (N,); ``progress``
    (B + 1,): the schedule's progress ``u`` at each sample; the strict problem's
    ``feedforward`` (m,; size 0 for the baseline) and the rows and command components it paces
    (:meth:`dvqp.step.Stepper.pace`); the relaxed problem's arrays (``relaxed_P`` ..
    ``relaxed_ub``; size 0 for the baseline), the time-scaled problem's (``scaled_P`` ..
    ``scaled_ub``; size 0 before a step was first slowed), the least-violation problem's
    (``ray_P`` .. ``ray_ub``, :mod:`dvqp.resolution.ray`; size 0 without it) and what its ``Q̇``
    block holds (``ray_eye``, ``ray_zero``), the tasks' weight ``ρ``, the right sides levels
    hold (``held``, (m,): :attr:`~dvqp.resolution.levels.Levels.fixed`, the ``b`` of their last
    level's relaxed problem, which the loop relaxes to; size 0 without levels) and room to keep
    ``b`` (m,) while a slowed step is tried; where the velocity is observed (``observed`` (n,),
    size 0: nowhere); the accuracy tally's ``log_sums`` (3,) and ``solves`` (1,) counted here;
    ``start`` (n,) the configuration the last step started from, ``made`` (15,) its compiled
    call's values, ``relaxed_made`` (12,) its relaxed attempt's and ``scaled_made`` (12,) its
    time-scaled one's (NaN: none), ``moved`` (2,) its move's; ``nominal`` (4,) scratch;
    ``verify`` (check every limit) and ``stride`` (rad, the largest joint motion of a step
    checked at its end only)."""

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
    kinds: Index
    flags: Array
    progress: Array
    feedforward: Array
    paced_rows: Index
    paced_components: Index
    relaxed_P: Array
    relaxed_q: Array
    relaxed_A: Array
    relaxed_G: Array
    relaxed_lb: Array
    relaxed_ub: Array
    scaled_P: Array
    scaled_q: Array
    scaled_A: Array
    scaled_b: Array
    scaled_G: Array
    scaled_lb: Array
    scaled_ub: Array
    ray_P: Array
    ray_q: Array
    ray_A: Array
    ray_G: Array
    ray_lb: Array
    ray_ub: Array
    ray_eye: Array
    ray_zero: Array
    task_weight: float
    held: Array
    saved_b: Array
    observed: Array
    log_sums: Array
    solves: Index
    start: Array
    made: Array
    relaxed_made: Array
    scaled_made: Array
    moved: Array
    nominal: Array
    verify: bool
    stride: float


def _values(attempt: Array) -> tuple[float, ...] | None:
    """An attempt's values as the loop left them (None: not made)."""
    return None if math.isnan(attempt[0]) else tuple(attempt.tolist())


class Followed(NamedTuple):
    """Where :meth:`Follower.run` left the run: the next step ``k``, the progress ``u``, the
    time the next step starts (``time.perf_counter``'s s) and the step ``k`` it hands over
    made (None: it stopped before step ``k``)."""

    k: int
    u: float
    started: float
    made: Made | None


def _problem(problem: Any, with_b: bool) -> tuple[Array, ...]:
    """A relaxed or time-scaled problem's arrays the loop writes: ``P``, ``q``, ``A``,
    (``b``), ``G`` ((0, columns) without constraints), ``lb``, ``ub``; of size 0 without the
    problem."""
    if problem is None:
        return (
            (np.zeros((0, 0)), np.zeros(0), np.zeros((0, 0)))
            + ((np.zeros(0),) if with_b else ())
            + (np.zeros((0, 0)), np.zeros(0), np.zeros(0))
        )
    G = problem.G if problem.G is not None else np.zeros((0, problem.P.shape[0]))
    b = (problem.b,) if with_b else ()
    return (problem.P, problem.q, problem.A, *b, G, problem.lb, problem.ub)


def _ray_constants(ray: Any, n: int) -> tuple[Array, Array]:
    """The least-violation problem's ``Q̇`` block (:func:`dvqp.resolution.ray.ray_constants`),
    of size 0 without the problem."""
    return (np.zeros((0, 0)), np.zeros(0)) if ray is None else ray_constants(n)


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
        """The schedule's progress ``u`` at each sample, (B + 1,) (written by the loop and,
        for the steps Python takes, by the run)."""
        self._packed: tuple[FollowArrays, Any] | None = None  # the arrays and their struct
        self.compiles = COMPILE == "always"
        """Whether :meth:`run` compiles the loop when the cache does not hold it (set by
        :meth:`compile`)."""
        self._runs_for: dict[tuple[Any, ...], bool] = {}  # arguments' types -> verdict
        self.off = False
        """The loop is not taken in this run (neither cached nor compiled): :meth:`run` returns
        at once, every step is Python's."""

    def _struct(self) -> tuple[FollowArrays, Any]:
        """The loop's arrays and their struct (packed again when the recorder has grown or
        the time-scaled problem has been made)."""
        a, solver = self.record.arrays, self.stepper.solver
        scaled = None if solver is None else solver.scaled
        kept = self._packed
        if (
            kept is not None
            and kept[0].qdot is a["qdot"]
            and kept[0].scaled_q.size == (0 if scaled is None else scaled.q.size)
        ):
            return kept
        rows, components = self.stepper.paced
        if solver is None:  # the baseline is neither paced (Stepper.pace) nor relaxed
            rows, components = rows[:0], components[:0]
        steps = a["qdot"].shape[0]
        arrays = FollowArrays(
            self.schedule.arrays,
            *(a[name] for name in ("solve_time", "solver_time", "step_time", "task_error")),
            a["level_error"],
            a["iterations"],
            a["substeps"],
            a["success"],
            a["qdot"],
            np.zeros(steps, np.int64),
            np.zeros(steps),
            self.progress,
            np.zeros(0) if solver is None else solver.feedforward,
            rows.astype(np.int64),
            components.astype(np.int64),
            *_problem(None if solver is None else solver.loop_relaxed, with_b=False),
            *_problem(scaled, with_b=True),
            *_problem(None if solver is None else solver.ray, with_b=False),
            *_ray_constants(None if solver is None else solver.ray, self.stepper.robot.n),
            0.0 if solver is None else float(solver.task_weight),
            np.zeros(0) if solver is None or solver.levels is None else solver.levels.fixed,
            np.zeros(0) if solver is None else np.zeros_like(solver.feedforward),
            np.zeros(0) if self.stepper.observed is None else self.stepper.observed,
            np.zeros(3),
            np.zeros(1, np.int64),
            np.zeros(self.stepper.robot.n),
            np.zeros(MADE),
            np.zeros(ATTEMPT),
            np.zeros(ATTEMPT),
            np.zeros(2),
            np.zeros(4),
            bool(self.verify),
            float(JOINT_STRIDE),
        )
        self._packed = (arrays, as_struct(arrays))
        return self._packed

    def compile(self, warm: bool) -> None:
        """Load the loop this run takes from the cache, or compile it if :data:`COMPILE`
        allows (``warm``: the run's first step compiled nothing; or the run is long,
        :data:`LONG_RUN`), without taking a step."""
        long = self.schedule.budget >= LONG_RUN
        self.compiles = COMPILE == "always" or (COMPILE == "warm" and (warm or long))
        self.run(0, 0.0, 0.0, until=0)

    def _runs(self, kernel: Any, args: tuple[Any, ...]) -> bool:
        """Whether ``kernel(*args)`` runs: loaded or compiled already, loaded from the cache
        now, or compiled at the call (:attr:`compiles`). Decided once for the arguments'
        types (a packed struct's numba type; it holds no array, so no run's memory is kept)."""
        key = (kernel, *(getattr(a, "_numba_type_", None) or type(a) for a in args))
        runs = self._runs_for.get(key)
        if runs is None:
            runs = self._runs_for[key] = self.compiles or ready(kernel, args)
        self.off = not runs  # nothing this run does compiles it later
        return runs

    def run(self, k: int, u: float, started: float, until: int | None = None) -> Followed:
        """The common steps from step ``k`` at progress ``u`` (the step starting at
        ``started``), until the schedule's end, its budget, the recorder's room, :data:`BATCH`
        steps or step ``until``; each recorded and counted. The step after them, made, is
        handed over when it is not common."""
        stepper, record, schedule = self.stepper, self.record, self.schedule
        handle = None if self.off else stepper.fused()
        if handle is None:
            return Followed(k, u, started, None)
        room = min(schedule.budget, record.arrays["qdot"].shape[0], k + BATCH)
        stop = room if until is None else min(until, room)
        arrays, f = self._struct()
        solver = stepper.solver
        if solver is None:
            kernel, args = follow_baseline, (stepper.struct, handle, f, k, u, started, stop)
        else:
            relaxed, pacing = solver.relaxed_attempt(), solver.pacing_attempt()
            ray = solver.ray_attempt()
            kernel, args = (
                follow,
                (
                    stepper.struct,
                    handle,
                    handle if relaxed is None else relaxed,
                    handle if pacing is None else pacing,
                    f,
                    k,
                    u,
                    started,
                    stop,
                    relaxed is not None,
                    pacing is not None,
                    handle if ray is None else ray,
                    ray is not None,
                ),
            )
        if not self._runs(kernel, args):
            return Followed(k, u, started, None)
        if solver is None:
            out = kernel(*args)
        else:
            arrays.log_sums[:] = solver.accuracy.log_sums
            arrays.solves[0] = 0
            out = kernel(*args)
            solver.followed()
            solver.accuracy.log_sums = [float(v) for v in arrays.log_sums]
            solver.accuracy.solves += int(arrays.solves[0])
        reached = int(out[1])
        if reached > k:
            self._taken(arrays, k, reached)
        if out[0] != HANDED:
            return Followed(reached, float(out[2]), float(out[3]), None)
        singular, moving = arrays.moved.tolist()
        made = Made(
            arrays.start.copy(),
            float(out[4]),
            tuple(arrays.made.tolist()),
            _values(arrays.relaxed_made),
            None if math.isnan(singular) else (singular, moving),
            _values(arrays.scaled_made),
        )
        return Followed(reached, float(out[2]), float(out[3]), made)

    def _taken(self, arrays: FollowArrays, first: int, end: int) -> None:
        """Steps ``first`` to ``end`` (excluded), taken by the loop (``arrays``): their
        statuses, and the refusals of the relaxed or slowed ones' strict problems."""
        record = self.record
        record.status[first:end] = KINDS[OPTIMAL]
        record.steps = end
        kinds = arrays.kinds[first:end]
        refused = kinds != OPTIMAL
        if refused.any():
            for kind in (RELAXED, SLOWED):
                record.status[first:end][kinds == kind] = KINDS[kind]
            assert self.stepper.solver is not None
            self.stepper.solver.count_refused(arrays.flags[first:end][refused])


@njit(inline="always")
def _begin(s, f, k, u):  # type: ignore[no-untyped-def]
    """Step ``k`` at progress ``u`` set up as Python sets it up: its start kept, the
    schedule's command and ``dt`` written, a time-scaled run paced (as
    :meth:`dvqp.step.Stepper.pace`), the sample it reaches named; returns its span."""
    a = f.schedule
    for i in range(f.start.shape[0]):
        f.start[i] = s.state.q[i]
    span = command_into(a, u, s.state.tool, s.command, f.nominal)
    s.dt[0] = a.dt
    if a.scaled:
        for i in range(f.feedforward.shape[0]):
            f.feedforward[i] = 0.0
        for j in range(f.paced_rows.shape[0]):
            f.feedforward[f.paced_rows[j]] = f.nominal[f.paced_components[j]]
    s.record.index[0] = k + 1
    return span


@njit(inline="always")
def _kept(s, f) -> bool:  # type: ignore[no-untyped-def]
    """The state reached keeps every verified limit (if verified) and the step moved no
    joint farther than the stride (no interior point to check): :func:`~dvqp.step.advance`
    takes it as it is."""
    return not f.verify or (s.checks.excess[1] <= 1.0 and s.motion[1] <= f.stride)


@njit(inline="always")
def _record(s, f, k, spent, iterations, solver_time, step_time, kind):  # type: ignore[no-untyped-def]
    """Step ``k`` taken as :func:`~dvqp.step.advance` and the recorder take it: its
    velocity observed and recorded with its errors, times (s) and kind."""
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
    f.solve_time[k] = spent
    f.iterations[k] = iterations
    f.solver_time[k] = solver_time
    f.step_time[k] = step_time
    f.kinds[k] = kind


@njit(inline="always")
def _handed(f, out, k, u, started, begun):  # type: ignore[no-untyped-def]
    """Step ``k`` handed to Python with its compiled call's values ``out`` (nothing else
    made)."""
    for i in range(MADE):
        f.made[i] = out[i]
    f.relaxed_made[0] = f.scaled_made[0] = f.moved[0] = math.nan
    return (HANDED, float(k), u, started, begun)


@njit(inline="always")
def _checked(a) -> bool:  # type: ignore[no-untyped-def]
    """An attempt's values ``a`` (12) hold an answer the check judged (accepted or refused;
    not a misfit, a failed update or rows that outgrew their copy)."""
    return (a[0] == SOLVED or a[0] == ACCEPTED) and a[4] != MISFIT


@njit(inline="always")
def _paced(f) -> bool:  # type: ignore[no-untyped-def]
    """This step is paced (time scaling): its refusal slows down before it relaxes."""
    paced = False
    for i in range(f.feedforward.shape[0]):
        paced = paced or f.feedforward[i] != 0.0
    return paced


@njit(separate=True)
def _move(s, f, x, clock):  # type: ignore[no-untyped-def]
    """The step ``x`` taken and the state it reaches evaluated (as :meth:`dvqp.step.
    Stepper.move`), kept in ``f.moved`` as ``(singular, seconds)``; whether it is taken as
    it is (regular and kept, :func:`_kept`)."""
    for i in range(s.x.shape[0]):
        s.x[i] = x[i]
    started = now(clock)
    singular = evaluate(s, True, MEASURE, CONCLUDE)
    f.moved[0], f.moved[1] = float(singular), now(clock) - started
    return singular == -1 and _kept(s, f)


@njit(inline="always")
def _relax(s, f, r):  # type: ignore[no-untyped-def]
    """The relaxed problem loaded (as :func:`~dvqp.resolution.levels.load_relaxed`) and its
    first attempt made (``r``); its values, also in ``f.relaxed_made``."""
    qp = s.qp
    load_columns(
        qp.P,
        qp.cost,
        qp.A,
        qp.G,
        qp.lb,
        qp.ub,
        f.relaxed_P,
        f.relaxed_q,
        f.relaxed_A,
        f.relaxed_G,
        f.relaxed_lb,
        f.relaxed_ub,
    )
    again = solve_dropped(r)
    for i in range(ATTEMPT):
        f.relaxed_made[i] = again[i]
    return again


@njit(inline="always")
def _slow(s, f, p):  # type: ignore[no-untyped-def]
    """The time-scaled problem loaded (:func:`~dvqp.resolution.qp.load_scaled`) and its
    first attempt made (``p``); its values, also in ``f.scaled_made``."""
    qp = s.qp
    load_scaled(
        qp.P,
        qp.cost,
        qp.A,
        qp.b,
        qp.G,
        qp.lb,
        qp.ub,
        f.feedforward,
        f.task_weight,
        f.scaled_P,
        f.scaled_q,
        f.scaled_A,
        f.scaled_b,
        f.scaled_G,
        f.scaled_lb,
        f.scaled_ub,
    )
    again = solve_dropped(p)
    for i in range(ATTEMPT):
        f.scaled_made[i] = again[i]
    return again


@njit
def follow(s, w, r, p, f, k, u, started, until, relaxing, pacing, e, proving):  # type: ignore[no-untyped-def]
    """A QP run's common steps from step ``k`` at progress ``u`` (the step starting at
    ``started``, s of ``time.perf_counter``'s clock), on the step's struct ``s``, the strict
    backend's packed attempt ``w`` (:meth:`~dvqp.resolution.qp.QPSolver.fused_attempt`), the
    relaxed backend's ``r`` (:meth:`~dvqp.resolution.qp.QPSolver.relaxed_attempt`; used if
    ``relaxing``), the time-scaled problem's ``p`` (:meth:`~dvqp.resolution.qp.QPSolver.
    pacing_attempt`; used if ``pacing``), the least-violation problem's ``e``
    (:meth:`~dvqp.resolution.qp.QPSolver.ray_attempt`; used if ``proving``) and the loop's
    arrays ``f`` (:class:`FollowArrays`), up to step ``until`` (excluded).

    Each step's strict problem is solved as :meth:`~dvqp.resolution.qp.QPSolver.solve` and
    its backend solve it: the warm attempt, and if it is refused the cold restart (the
    backend's ``after_warm``); after a refusal the next step's first attempt is the cold
    one. Refused, a paced step (time scaling) is slowed: the time-scaled problem loaded
    (:func:`~dvqp.resolution.qp.load_scaled`), its warm attempt made, ``b`` left at the
    progress it makes; at fixed timing the step is relaxed: the relaxed problem loaded and
    its warm attempt made. A step is taken here when its answer was accepted (strict, or the
    relaxed one's warm attempt) and the state it reaches is regular and kept; else it is
    handed to Python with what was made of it, the strict backend's ``mode`` as it was
    before the step (Python makes its cold restart again: a restart re-forms DAQP's problem
    from its data alone, the same answer).

    Returns
    -------
    tuple of 5 floats
        ``(how, k, u, started, begun)``: :data:`STOPPED` before step ``k``, or
        :data:`HANDED` with step ``k`` made, its resolution begun at ``begun``, its compiled
        call's values (:func:`~dvqp.step.stages.resolve_move`'s) in ``f.made``, and if its
        relaxed attempt was made too, that attempt's values in ``f.relaxed_made`` (NaN:
        not made), and the move's ``(singular, seconds)`` in ``f.moved`` (NaN: not moved).
    """
    clock = w.call.handles[H_CLOCK]
    a, mode = f.schedule, w.call.mode
    while k < until and not u >= a.n - 1e-9:
        begun = now(clock)
        span = _begin(s, f, k, u)
        first = mode[0]
        out = resolve_move(s, w)
        if out[0] == MOVED:  # the warm answer accepted, its state evaluated
            if out[1] != -1.0 or not _kept(s, f):
                return _handed(f, out, k, u, started, begun)
            kind, iterations, solver_time, rate = OPTIMAL, int(out[5]), out[6], 1.0
            moving = out[2]
            add_kernel_metrics(f.log_sums, out[7:15])
        else:
            if out[0] != ATTEMPTED or not _checked(out[3:15]):
                return _handed(f, out, k, u, started, begun)
            _handed(f, out, k, u, started, begun)  # what Python finishes if it must
            kind, iterations, solver_time, rate = _refused(
                s, w, r, p, f, k, out, relaxing, pacing, e, proving
            )
            if kind < 0:
                mode[0] = first
                return (HANDED, float(k), u, started, begun)
            moving = f.moved[1]
        f.solves[0] += 1
        ended = now(clock)
        _record(s, f, k, ended - begun - moving, iterations, solver_time, ended - started, kind)
        started = ended
        u += rate * span
        k += 1
        f.progress[k] = u
    return (STOPPED, float(k), u, started, 0.0)


@njit(separate=True)  # compiled once, called by symbol: the loop stays small to compile
def _refused(s, w, r, p, f, k, out, relaxing, pacing, e, proving):  # type: ignore[no-untyped-def]
    """Step ``k`` whose strict attempt (``out``, :func:`~dvqp.step.stages.resolve_move`'s) was
    refused or a cold one: restarted cold if it was warm (the backend's ``after_warm``;
    certified without a call when the multipliers the workspace holds prove the refusal, as
    the restart would find them), then, still refused, slowed if paced, else relaxed, and
    moved. A proof that the strict problem admits no answer is kept for the strict restarts:
    DAQP's direction of the last refusal it found or the multipliers held, if either proves
    this step's refusal, else the least-violation problem's (``e``, if ``proving``:
    before the cold restart, which they may then spare, or after a refused one), else (none
    held, or it proved nothing) the relaxed or time-scaled answer's (:func:`solvers.daqp_c.
    hold_multipliers`), not with levels (Python's cascade, which counts the refusal's
    iterations, holds none). Returns ``(kind, iterations, solver_time, rate)`` of the step
    taken, its kind −1 (with ``b`` as it was) when it cannot be taken here."""
    clock, mode, qp = w.call.handles[H_CLOCK], w.call.mode, s.qp
    answer, warm, held = _confirmed(s, f, e, w, out, proving)
    if not _checked(answer):
        return (-1, 0, 0.0, 0.0)
    solver_time = answer[3] + warm
    if answer[0] == ACCEPTED:  # the strict answer, cold
        mode[0] = WARM
        if not _move(s, f, w.call.x, clock):
            return (-1, 0, 0.0, 0.0)
        add_kernel_metrics(f.log_sums, answer[4:12])
        return (OPTIMAL, int(answer[2]), solver_time, 1.0)
    f.flags[k] = answer[1]
    if f.held.shape[0] > 0 and nested_keeps(s):  # levels met in least squares: Python's
        return (-1, 0, 0.0, 0.0)
    if _paced(f):  # slowed along the path
        if not pacing:
            return (-1, 0, 0.0, 0.0)
        again = _slow(s, f, p)
        if again[0] == ACCEPTED and not held:  # the next strict restart's proof to try
            hold_multipliers(p, w)
        if again[0] != ACCEPTED or p.call.mode[0] != WARM:
            return (-1, 0, 0.0, 0.0)
        rate = min(max(p.call.x[s.x.shape[0]], 0.0), 1.0)
        for i in range(qp.b.shape[0]):  # b at the progress the step makes
            f.saved_b[i] = qp.b[i]
            qp.b[i] = qp.b[i] - (1.0 - rate) * f.feedforward[i]
        if not _move(s, f, p.call.x, clock):
            for i in range(qp.b.shape[0]):
                qp.b[i] = f.saved_b[i]
            return (-1, 0, 0.0, 0.0)
        add_kernel_metrics(f.log_sums, again[4:12])
        return (SLOWED, int(again[2]), solver_time + again[3], rate)
    if not relaxing:  # relaxed, at fixed timing
        return (-1, 0, 0.0, 0.0)
    levels = f.held.shape[0] > 0  # their last level relaxed, those above held at b
    for i in range(f.held.shape[0]):
        f.held[i] = qp.b[i]
    again = _relax(s, f, r)
    if again[0] == ACCEPTED and not held and not levels:
        hold_multipliers(r, w)
    if again[0] != ACCEPTED or r.call.mode[0] != WARM or not _move(s, f, r.call.x, clock):
        return (-1, 0, 0.0, 0.0)
    add_kernel_metrics(f.log_sums, again[4:12])
    iterations = int(again[2]) + (int(answer[2]) if levels else 0)  # as the cascade counts
    return (RELAXED, iterations, solver_time + again[3], 1.0)


@njit
def nested_keeps(s) -> bool:  # type: ignore[no-untyped-def]
    """Whether the nested step of the step's levels (:func:`~dvqp.resolution.pinv.pinv_step`,
    as :meth:`~dvqp.resolution.levels.Levels.nested` makes it) keeps every bound and
    constraint: then no limit binds and Python takes it, without relaxing a level."""
    qp, p = s.qp, s.pinv
    x, info = np.empty(qp.cost.shape[0]), np.zeros(3)
    status = pinv_step(
        qp.A, qp.b, s.tasks.levels, p.rows, qp.cost, p.weights, qp.P, True, 0.0, info, x
    )
    if status != -1:
        return False
    for i in range(x.shape[0]):
        if not (qp.lb[i] <= x[i] <= qp.ub[i]):
            return False
    for r in range(qp.h.shape[0]):
        v = 0.0
        for c in range(x.shape[0]):
            v += qp.G[r, c] * x[c]
        if not v <= qp.h[r]:
            return False
    return True


@njit(inline="always")
def _confirmed(s, f, e, w, out, proving):  # type: ignore[no-untyped-def]
    """The strict problem's answer after its attempt ``out`` (:func:`_refused`'s): restarted
    cold if that attempt was warm (certified without a call when DAQP's direction or the
    multipliers held prove the refusal, as the restart would find them), and a proof kept
    for the next restarts. Returns ``(answer, seconds, held)``: the answer's 12 values, the
    seconds inside DAQP besides the answer's own (the warm attempt's, the least violation's)
    and whether what the workspace holds proves this step's refusal, or the least
    violation's multipliers were just held (then the fallback's are not held over them)."""
    mode = w.call.mode
    answer, warm, tried, held = out[3:15], 0.0, False, False
    if mode[0] == WARM:  # the cold restart; its time counts the warm attempt's too
        mode[0] = RESTART
        if proves(w.call):  # the restart's certificate, found as it would find it
            answer = certified(w.call.x)
        else:
            if proving:  # a proof for the restart to try first
                warm, held = _prove(s, f, e, w)
                tried = True
            answer = attempt(w.call)
        warm += out[6]
    if proving and not tried and answer[0] != ACCEPTED and answer[1] != CERTIFIED:
        if proves(w.call):  # DAQP's direction of the refusal it solved, or those held
            held = True
        else:
            spent, held = _prove(s, f, e, w)
            warm += spent
    return answer, warm, held or answer[1] == CERTIFIED  # keep what proved it


@njit(inline="always")
def _prove(s, f, e, w):  # type: ignore[no-untyped-def]
    """The least-violation problem loaded (its ``Q̇`` block ``ε I``, no cost:
    :mod:`dvqp.resolution.ray`) and its first attempt made (``e``); its answer's multipliers,
    if accepted, held in the strict backend's workspace (``w``), where its restarts try them
    as a proof (:func:`solvers.daqp_c.hold_multipliers`). Returns the seconds inside DAQP
    and whether they were held (not if refused, or if its copy's capacity would change)."""
    qp = s.qp
    load_columns(
        f.ray_eye,
        f.ray_zero,
        qp.A,
        qp.G,
        qp.lb,
        qp.ub,
        f.ray_P,
        f.ray_q,
        f.ray_A,
        f.ray_G,
        f.ray_lb,
        f.ray_ub,
    )
    again = solve_dropped(e)
    if again[0] == ACCEPTED:
        hold_multipliers(e, w)
    return (again[3] if again[0] >= 0.0 else 0.0), again[0] == ACCEPTED


@njit
def follow_baseline(s, clock, f, k, u, started, until):  # type: ignore[no-untyped-def]
    """:func:`follow` for the baseline (``clock``: :func:`solvers.clock.address`): its
    step and move in one call (:func:`~dvqp.step.stages.resolve_move_baseline`); a handed
    step's values are that call's three, then NaN."""
    a = f.schedule
    while k < until and not u >= a.n - 1e-9:
        begun = now(clock)
        span = _begin(s, f, k, u)
        status, singular, moving = resolve_move_baseline(s, clock)
        if status != MOVED or singular != -1 or not _kept(s, f):
            return _handed(f, (status, singular, moving, *NOT_ATTEMPTED), k, u, started, begun)
        ended = now(clock)
        spent = ended - begun - moving
        _record(s, f, k, spent, -1, spent, ended - started, OPTIMAL)
        started = ended
        u += span
        k += 1
        f.progress[k] = u
    return (STOPPED, float(k), u, started, 0.0)
