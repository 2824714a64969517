"""A resolver's step compiled for one run: load a configuration, resolve a step, move.

:class:`Stepper` lays out the resolver's spec once (:func:`dvqp.step.build.build`), packs its
arrays into one numba struct and runs the compiled stages (:mod:`dvqp.step.stages`) on it, with
the parts of your own in between (:mod:`dvqp.step.hooks`) and the QP backend (or the baseline's
pseudoinverse) after :func:`~dvqp.step.stages.prepare`. Everything a run does goes through it:
the common step, split substeps and interior points of a large step
(:func:`dvqp.step.advance.advance`), the console's live steps.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import replace
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

import solvers
from dvqp.errors import ParameterError, ShapeError, SingularConfigurationError, TaskLevelError
from dvqp.geometry.obstacle import ObstacleSet
from dvqp.kinematics.robot import Robot
from dvqp.kinematics.state import KinematicState, singular_frame
from dvqp.limits import Bounds, Constraint, Limit, VelocityDamper
from dvqp.objective import Term
from dvqp.resolution.qp import Answer, QPSolver
from dvqp.resolution.spec import unmeetable
from dvqp.resolution.step import Resolver
from dvqp.step import stages
from dvqp.step.arrays import RecordArrays
from dvqp.step.build import lay_out
from dvqp.step.verification import Verification
from dvqp.workspace import as_struct
from solvers import clock

Array = NDArray[np.float64]


def paced_rows(tool: NDArray[np.int64]) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """The rows of the tool tasks ``tool`` (``TaskArrays.tool``: first row, count,
    components) and the command's component each takes, as two index arrays."""
    rows = [(start + i, c) for start, count, *cs in tool for i, c in enumerate(cs[:count])]
    return (
        np.array([r for r, _ in rows], dtype=np.intp),
        np.array([c for _, c in rows], dtype=np.intp),
    )


def observing(limits: tuple[Limit, ...]) -> list[Limit]:
    """The ``limits`` that keep the velocity they are shown (:meth:`Limit.observe`)."""
    return [limit for limit in limits if limit.observes]


def observed_into(observers: list[Limit]) -> Array | None:
    """The one array where compiled code writes the velocity the ``observers`` (limits that
    observe it) are shown (size 0 without observers), or None when one observes it only in
    Python (:meth:`Limit.observed_into`) or there are several."""
    if not observers:
        return np.zeros(0)
    into = [limit.observed_into() for limit in observers]
    return into[0] if len(into) == 1 else None


def _bad_command() -> ParameterError:
    """The error of a step command with a NaN or an infinity."""
    return ParameterError("command", "must be finite (no NaN or inf)")


class Made(NamedTuple):
    """A step's compiled call made by a run's compiled loop and handed back to Python to
    finish (:meth:`Stepper.resolve_and_move`): the configuration it started from (rad, (n,)),
    when its resolution started (``time.perf_counter``'s s) and the call's values
    (:func:`~dvqp.step.stages.resolve_move`'s, or the baseline's). After the strict
    problem's warm attempt was refused there, the loop may have made the cold restart, then
    the relaxed problem's attempt (``relaxed``: its values, :meth:`~dvqp.resolution.qp.
    QPSolver.relaxed_attempt`) or the time-scaled one's (``scaled``), and, an answer
    accepted, evaluated the state it reaches (``moved``: ``(singular, seconds)`` as
    :func:`~dvqp.step.stages.resolve_move`'s); Python makes the backend's cold restart again
    from the warm attempt's values (a restart re-forms DAQP's problem from its data alone: the
    same answer)."""

    start: Array
    started: float
    values: tuple[float, ...]
    relaxed: tuple[float, ...] | None = None
    moved: tuple[float, float] | None = None
    scaled: tuple[float, ...] | None = None


class Resolution(NamedTuple):
    """How a step's joint velocity (:attr:`Stepper.x`) was found: ``success``, ``status``
    (``"optimal"``, ``"slowed"``, ``"relaxed"``, ``"braking"`` or why it failed), the
    backend's ``iterations``, the time inside its calls and of the whole resolution (s), and
    the fraction of the nominal progress made (:meth:`Stepper.pace`; 1 without it)."""

    success: bool
    status: str
    iterations: int | None
    solver_time: float
    solve_time: float
    rate: float = 1.0


class Stepper(Verification):
    """The compiled step of ``resolver`` on ``robot`` in a pipe of ``radius`` (m).

    Parameters
    ----------
    robot, radius, resolver
        What steps.
    q0
        The run's start, rad: parts of your own are sized there.
    dt
        The run's step, s (a step may use another).
    obstacles
        Obstacles whose clearances the diagnostics measure (default none).
    samples
        The recorder's per-sample arrays (:class:`~dvqp.step.arrays.RecordArrays` fields):
        each state concluded while :attr:`record_at` is set is written there.

    Attributes
    ----------
    state : KinematicState
        Read-only views of the loaded state.
    x : ndarray, shape (n,)
        The joint velocity of the last resolved step, rad/s.
    """

    def __init__(
        self,
        robot: Robot,
        radius: float,
        resolver: Resolver,
        q0: ArrayLike,
        dt: float,
        obstacles: ObstacleSet | None = None,
        samples: Mapping[str, np.ndarray] | None = None,
    ) -> None:
        spec = resolver.spec
        self.robot, self.resolver = robot, resolver
        self.obstacles = ObstacleSet() if obstacles is None else obstacles
        """The obstacles the diagnostics measure (their ``labels`` name them)."""
        self.layout, self.arrays = lay_out(robot, radius, resolver, q0, dt, obstacles, samples)
        plan = self.layout.plan
        self.struct = as_struct(self.arrays)
        assert plan.qp is not None and plan.checks is not None
        tasks = self.layout.tasks
        self.solver = resolver.solver(
            plan.qp, spec.task_weight, tasks.levels, self.layout.row_weights
        )
        self.hooks = self.layout.hooks
        self._prepare = stages.prepare_baseline if self.arrays.pinv.baseline else stages.prepare
        self.state = KinematicState.view(plan.state, radius, plan.k, plan.names)
        self.x = self.arrays.x
        self.record_at = self.arrays.record.index
        """(1,) int64: row of the samples the next concluded state is written to (−1: none)."""
        self.excess_now = plan.checks.excess
        """(2,): ``[value, ratio]`` of the loaded state's worst excess."""
        self.motion = self.arrays.motion
        """(2,): ``[‖A x − b‖∞, max |dt x|]`` of the last :meth:`move`."""
        self.level_error = tasks.level_error
        """(L,): each level's ``‖A_k x − b_k‖∞`` of the last :meth:`move` (task units per s),
        levels by priority (1 first)."""
        self.limits: tuple[Limit, ...] = spec.limits
        self._observers = observing(spec.limits) if resolver.holds_limits else []
        self.observed = observed_into(self._observers)
        """Where the velocity of a step is observed in compiled code (:meth:`Limit.
        observed_into`; size 0: nowhere), or None: only :meth:`observe` observes it."""
        self.stopping = False
        """Braking steps: the hard tasks' right sides and the cost's linear part are 0 (the
        tool and every task held still, λ = 0), a damper holds a drift below its safe value
        instead of pulling it back (right side at least 0), and Q̇ = 0 is taken when it is
        feasible (:meth:`~dvqp.resolution.qp.QPSolver.solve`)."""
        self.paced = paced_rows(tasks.tool)
        """The tool tasks' rows and the command's components they take (:meth:`pace`), two
        index arrays."""
        if tasks.levels.shape[0] > 2:
            self._check_levels(q0, dt)

    def _check_levels(self, q0: ArrayLike, dt: float) -> None:
        """Refuse a level that cannot be met even alone at ``q0`` (its rows as the step writes
        them: :func:`~dvqp.resolution.spec.unmeetable`).

        Raises
        ------
        TaskLevelError
            Such a level.
        """
        if not self.load(q0):
            return  # singular: start() says so
        self.prepare(np.zeros(4), dt)
        breaks, A = self.layout.tasks.levels, self.arrays.qp.A
        names = self.resolver.spec.level_names
        for level in range(breaks.shape[0] - 1):
            why = unmeetable(A[breaks[level] : breaks[level + 1]])
            if why is not None:
                raise TaskLevelError(level + 1, names[level], why)

    def load(self, q: ArrayLike) -> bool:
        """Evaluate the state at ``q`` (rad); False if a guarded frame is on the pipe axis."""
        self.arrays.state.q[:] = q
        return self._evaluate(False) == -1

    def move(self) -> bool:
        """Evaluate the state reached by :attr:`x` over ``dt`` from the loaded one; False if
        singular. :attr:`motion` then holds the step's task error and largest joint motion."""
        return self._evaluate(True) == -1

    def _evaluate(self, integrate: bool) -> int:
        s, hooks = self.struct, self.hooks
        if not hooks.active:
            return int(stages.evaluate(s, integrate, stages.MEASURE, stages.CONCLUDE))
        status = int(stages.evaluate(s, integrate, stages.MEASURE, stages.MEASURE))
        if status != -1:
            return status
        for hook in hooks.measured:
            hook()
        stages.evaluate(s, False, stages.ASSESS, stages.DAMPERS)
        for hook in hooks.assessed:
            hook()
        return int(stages.evaluate(s, False, stages.CONCLUDE, stages.CONCLUDE))

    def start(self, q0: ArrayLike) -> None:
        """Load the run's start: the limits' floors are ``min(safe, value there)``, the
        limits that remember motion start at rest, the backends cold, no sample recorded.

        Raises
        ------
        SingularConfigurationError
            A guarded frame of ``q0`` lies on the pipe axis.
        """
        checks = self.arrays.checks
        for limit in self.limits:
            limit.reset()
        if self.solver is not None:
            self.solver.reset()
        if not self.load(q0):
            raise self.singular()
        np.minimum(checks.safe, checks.values, out=checks.floor)
        checks.lowest[:], checks.settled[:], checks.row[0] = np.inf, np.inf, -1
        self.load(q0)  # again, against the floors: the start's excess (and sample)

    def singular(self) -> SingularConfigurationError:
        """The error of the loaded configuration, singular."""
        s = self.arrays.state
        rho = np.hypot(s.origins[:, 0], s.origins[:, 1])
        frame = int(np.argmin(rho))
        return singular_frame(self.robot, frame, s.origins[frame], s.q.copy())

    @property
    def broken(self) -> bool:
        """The loaded state breaks a verified limit by more than its tolerance."""
        return not self.excess_now[1] <= 1.0

    def resolve(self, command: Array, dt: float) -> Resolution:
        """The step from the loaded state for the tool command ``command`` (4,) over ``dt``
        (s): :attr:`x` and how it was found (its task error is known once it is integrated,
        :meth:`move`).

        Raises
        ------
        SingularConfigurationError
            The baseline met a (nearly) singular task Jacobian.
        """
        started = time.perf_counter()
        status = self.prepare(command, dt)
        prepared = time.perf_counter()
        if self.solver is None:
            if status != -1:
                raise self._pinv_error(status)
            return Resolution(True, "optimal", None, prepared - started, prepared - started)
        if status != -1:
            return self._crossed(status, started)
        return self._resolved(self.solver.solve(rest=self.stopping), started)

    def resolve_and_move(
        self, command: Array, dt: float, made: Made | None = None
    ) -> tuple[Resolution, bool | None]:
        """:meth:`resolve`, and when its answer is taken in the compiled call that wrote the
        QP (the strict problem's warm attempt accepted: :func:`~dvqp.step.stages.
        resolve_move`), :meth:`move` made in that call too: its result, else None (then
        call :meth:`move`). A run with parts of your own, a stop's steps, levels or watched
        backend calls resolve as :meth:`resolve` does.

        ``made``: that compiled call already made, for ``command`` and ``dt``, by a run's
        compiled loop (:func:`dvqp.motion.follow.follow`, which stops at a step it cannot
        take as it is): this finishes the step from its values."""
        solver = self.solver
        if made is not None:
            if solver is None:
                return self._baseline_moved(made.values, made.started)
            if made.relaxed is not None or made.scaled is not None or made.moved is not None:
                return self._finished(solver, made)
            return self._fused(solver, made.values, made.started)
        if self.hooks.active or self.stopping:
            return self.resolve(command, dt), None
        if solver is None:
            started = time.perf_counter()
            self._command(command, dt)
            values = stages.resolve_move_baseline(self.struct, clock.address())
            return self._baseline_moved(values, started)
        packed = solver.fused_attempt()
        if packed is None:
            return self.resolve(command, dt), None
        started = time.perf_counter()
        self._command(command, dt)
        return self._fused(solver, stages.resolve_move(self.struct, packed), started)

    def fused(self) -> Any:
        """What a run's compiled loop resolves its common steps with, when it may
        (:func:`dvqp.motion.follow.follow`): the strict backend's packed attempt
        (:meth:`~dvqp.resolution.qp.QPSolver.fused_attempt`), or for the baseline the clock's
        address (:func:`solvers.clock.address`); None when the steps resolve in Python (parts
        of your own, a stop's steps, levels, watched backend calls, a limit that observes the
        velocity only in Python)."""
        if self.hooks.active or self.stopping or self.observed is None:
            return None
        if self.solver is None:
            return clock.address()
        return self.solver.fused_attempt()

    def _fused(
        self, solver: QPSolver, out: tuple[float, ...], started: float
    ) -> tuple[Resolution, bool | None]:
        """The step whose strict attempt :func:`~dvqp.step.stages.resolve_move` made (its
        values ``out``; the resolution started at ``started``, ``time.perf_counter``'s s)."""
        status = int(out[0])
        if status == stages.MOVED:  # the resolution's time without the evaluation's
            taken = solver.took(out[3:])
            spent = time.perf_counter() - started - out[2]
            found = Resolution(True, "optimal", taken.iterations, taken.solver_time, spent)
            return found, out[1] == -1
        if status == stages.BAD_COMMAND:
            raise _bad_command()
        if status != stages.ATTEMPTED:
            return self._crossed(status, started), None
        return self._resolved(solver.solve(attempted=out[3:]), started), None

    def _finished(self, solver: QPSolver, made: Made) -> tuple[Resolution, bool | None]:
        """The step whose strict attempt, and maybe its relaxed attempt and move, the loop
        made (``made``): the resolution goes on from their values."""
        answer = solver.solve(
            attempted=made.values[3:], relaxed_values=made.relaxed, scaled_values=made.scaled
        )
        if made.moved is None:
            return self._resolved(answer, made.started), None
        singular, moving = made.moved
        found = self._resolved(answer, made.started + moving)  # less the evaluation's time
        return found, singular == -1

    def _baseline_moved(
        self, values: tuple[float, ...], started: float
    ) -> tuple[Resolution, bool | None]:
        """The baseline's step made by :func:`~dvqp.step.stages.resolve_move_baseline` (its
        ``values``), as :meth:`resolve_and_move` returns it."""
        status, singular, moving = values[:3]
        spent = time.perf_counter() - started - moving
        if status == stages.MOVED:
            return Resolution(True, "optimal", None, spent, spent), singular == -1
        if status == stages.BAD_COMMAND:
            raise _bad_command()
        raise self._pinv_error(int(status))

    def _crossed(self, joint: int, started: float) -> Resolution:
        """The step whose bounds on ``joint`` cross: failed."""
        lb, ub = self.arrays.qp.lb[joint], self.arrays.qp.ub[joint]
        why = f"failed: the bounds on joint{joint + 1}'s velocity cross ({lb:.4g} > {ub:.4g} rad/s)"
        return Resolution(False, why, None, 0.0, time.perf_counter() - started)

    def _resolved(self, answer: Answer, started: float) -> Resolution:
        """The resolver's ``answer`` as the step's :attr:`x` and resolution."""
        if answer.x is not None:
            self.x[:] = answer.x
        return Resolution(
            answer.x is not None,
            answer.status,
            answer.iterations,
            answer.solver_time,
            time.perf_counter() - started,
            answer.rate,
        )

    def pace(self, feedforward: Array | None) -> None:
        """Let the next steps slow along ``feedforward``, the tool's nominal DV velocity in
        the command (m/s, rad/s; shape (4,)), before they relax the task (time-scaled path
        following, :attr:`~dvqp.resolution.qp.QPSolver.feedforward`); None: no time scaling.
        The baseline has no such choice: its steps always make the whole progress."""
        if self.solver is None:
            return
        v = self.solver.feedforward
        v[:] = 0.0
        if feedforward is not None:
            rows, components = self.paced
            v[rows] = feedforward[components]

    def prepare(self, command: Array, dt: float) -> int:
        """Write the problem of a step from the loaded state for ``command`` (4,) over ``dt``
        (s), without solving it (:meth:`resolve` solves it): −1, or the first joint whose
        bounds cross (QP), or a status of the baseline (its step is then not defined)."""
        a, s, hooks = self.arrays, self.struct, self.hooks
        self._command(command, dt)
        split = bool(hooks.prepared) or self.stopping
        status = int(self._prepare(s, stages.ROWS, stages.ROWS if split else stages.CLOSE))
        if status == stages.BAD_COMMAND:
            raise _bad_command()
        if split:
            for hook in hooks.prepared:
                hook()
            if self.stopping:
                a.qp.b[:], a.qp.cost[:] = 0.0, 0.0
                held = a.qp.h[: a.dampers.distance.shape[0]]  # the damper rows come first
                np.maximum(held, 0.0, out=held)
            status = int(self._prepare(s, stages.CLOSE, stages.CLOSE))
        return status

    def _command(self, command: Array, dt: float) -> None:
        """The step's command (4,) and ``dt`` (s), written for the compiled stages."""
        if np.shape(command) != (4,):
            raise ShapeError("command", (4,), np.shape(command))
        self.arrays.command[:] = command
        self.arrays.dt[0] = dt

    def _pinv_error(self, status: int) -> SingularConfigurationError:
        if status == stages.INDEFINITE_METRIC:
            return SingularConfigurationError("the soft tasks' metric is not positive definite")
        level = int(self.arrays.pinv.info[2])
        names = self.resolver.spec.level_names
        which = f" of level {level + 1} ({names[level]})" if len(names) > 1 else ""
        return SingularConfigurationError(f"task Jacobian{which} is not finite")

    def record_into(self, samples: Mapping[str, np.ndarray]) -> None:
        """Write the samples of the states concluded from now on into ``samples`` (the
        recorder's arrays, e.g. grown; :attr:`record_at` stays the same array)."""
        names = [f for f in RecordArrays.__dataclass_fields__ if f != "index"]
        record = replace(self.arrays.record, **{f: samples[f] for f in names})
        self.arrays = replace(self.arrays, record=record)
        self.struct = as_struct(self.arrays)

    def observe(self, qdot: Array, dt: float) -> None:
        """Tell the limits that remember motion (acceleration) the velocity applied."""
        for limit in self._observers:
            limit.observe(qdot, dt)

    def rows(self, limit: Limit) -> Constraint | Bounds:
        """What ``limit`` put in the problem of the last :meth:`prepare`: its rows that apply
        (``h`` finite; labelled), or for a box limit the box of all box limits, intersected."""
        qp, blocks = self.arrays.qp, self.layout.blocks
        block = next((b for b in blocks if b.limit is limit and b.damper), None)
        if id(limit) in self.hooks.constraints:
            G, h = (self.layout.plan.view(slot) for slot in self.hooks.constraints[id(limit)])
            named = self.hooks.describes.get(id(limit))
            labels = named() if named is not None else tuple(f"row{i}" for i in range(h.size))
        elif block is not None:
            rows = slice(
                block.start - self.layout.damper_values, block.stop - self.layout.damper_values
            )
            G, h, labels = qp.G[rows], qp.h[rows], block.labels
        elif isinstance(limit, VelocityDamper):  # it has no row (e.g. no obstacle)
            return Constraint(np.zeros((0, qp.G.shape[1])), np.zeros(0))
        else:
            return Bounds(qp.lb.copy(), qp.ub.copy())
        applies = np.isfinite(h)
        kept = tuple(np.asarray(labels, dtype=object)[applies])
        return Constraint(G[applies], h[applies], lambda: kept)

    @property
    def objective(self) -> Term:
        """``w`` and ``∂w/∂Q`` (n,) of the loaded state (copies)."""
        o = self.arrays.objective
        return Term(float(o.value[0]), o.gradient.copy())

    def problem(self) -> solvers.Problem:
        """The strict QP of the last :meth:`resolve` (a validated copy)."""
        qp = self.arrays.qp
        G, h = (qp.G, qp.h) if qp.h.shape[0] else (None, None)
        return solvers.Problem(qp.P, qp.cost, qp.A, qp.b, G, h, qp.lb, qp.ub)
