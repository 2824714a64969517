"""The compiled step of a run: evaluate a state, solve, integrate, verify — or hand back.

:func:`compile_step` builds a :class:`CompiledStep` when every part of the resolver's spec
(tasks, objective terms, limits, obstacle shapes) provides a kernel, the robot's joints are
revolute or prismatic, and the resolver is the QP or the baseline; otherwise it returns None and
the run takes the reference path. :meth:`CompiledStep.step` does the common step entirely on
the plan's buffers: the resolver's answer, integrated and verified exactly against every limit
(the same values, floors and tolerances as :func:`dvqp.limits.excess.worst_excess`). Whatever
is not the common step — a QP the backend cannot solve (the relaxed retry, braking), a step
that breaks a limit (halving), a large step whose straight motion must be checked at interior
points, a singular configuration — returns None, and the caller runs the reference
:func:`dvqp.motion.advance.advance` for that step, which decides exactly as before.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import numpy as np
from numba import njit
from numpy.typing import NDArray

from dvqp.compiled import ownership
from dvqp.compiled.fusion import fuse
from dvqp.compiled.kinematics import CompiledModel
from dvqp.compiled.pinv import CompiledPinv
from dvqp.compiled.plan import Kernel, StepPlan
from dvqp.compiled.qp import CompiledQP
from dvqp.compiled.record import sample_kernel
from dvqp.compiled.solve import Answer, finish, limit_kernels, task_kernels, verifier_kernels
from dvqp.geometry.obstacle import ObstacleSet
from dvqp.kinematics.robot import Robot
from dvqp.kinematics.state import KinematicState
from dvqp.motion.advance import JOINT_STRIDE
from dvqp.objective.objective import Objective
from dvqp.resolution.pinv import PseudoinverseResolver
from dvqp.resolution.qp_resolver import QPResolver
from dvqp.resolution.spec import StepSpec
from dvqp.resolution.step import Resolver

Array = NDArray[np.float64]


@njit(cache=True)
def worst_excess(values: Array, floor: Array, tolerance: Array, out: Array) -> None:
    """``out = [value, ratio]`` of the largest ``(floor − value)/tolerance`` (−inf if none)."""
    best_v, best_r = -math.inf, -math.inf
    for i in range(values.shape[0]):
        over = floor[i] - values[i]
        ratio = over / tolerance[i]
        if ratio > best_r or ratio != ratio:  # a NaN is the worst (never "kept")
            best_v, best_r = over, ratio
            if ratio != ratio:
                break
    out[0], out[1] = best_v, best_r


@njit(cache=True)
def summary(origins, axes, pairs, points, links, out) -> None:  # type: ignore[no-untyped-def]
    """``out = [tilt, self distance, min clearance, probe clearance]`` of a state, as the
    recorder's reference diagnostics (rad, m, m, m; inf where nothing is measured)."""
    m = origins.shape[0] - 1
    ox, oy = origins[m, 0], origins[m, 1]
    u = (axes[m, 0] * ox + axes[m, 1] * oy) / math.hypot(ox, oy)
    out[0] = math.acos(max(-1.0, min(1.0, u)))
    out[1] = math.inf
    for p in range(pairs.shape[0]):
        out[1] = min(out[1], pairs[p])
    out[2], out[3] = math.inf, math.inf
    for j in range(points.shape[0]):
        for i in range(points.shape[1]):
            out[2] = min(out[2], points[j, i])
        for i in range(links.shape[1]):
            out[2] = min(out[2], links[j, i])
        out[3] = min(out[3], points[j, points.shape[1] - 1], links[j, links.shape[1] - 1])


@njit(cache=True)
def clear(value: Array, gradient: Array) -> None:
    """Zero the objective's accumulators before its terms add to them."""
    value[0] = 0.0
    gradient[:] = 0.0


@dataclass
class CompiledStep:
    """A resolver's step compiled for one run (see the module docstring; build it with
    :func:`compile_step`).

    Attributes
    ----------
    evaluate : callable
        One fused call evaluating the state at ``plan.state.q``: kinematics, geometry,
        objective, verification values, worst excess, diagnostics; −1, or the index of a
        singular frame.
    prepare : callable
        One fused call writing the tasks' rows and the solver's data (the QP, or the
        baseline's step); −1, or a failure status.
    excess : ndarray, shape (2,)
        ``[value, ratio]`` of the loaded state's worst excess against the run's start.
    diagnostics : ndarray, shape (4,)
        ``[tilt, self distance, min clearance, probe clearance]`` of the loaded state.
    """

    robot: Robot
    plan: StepPlan
    resolver: Resolver
    verify: bool
    solver: CompiledQP | CompiledPinv
    evaluate: Callable[[], int]
    prepare: Callable[[], int]
    floor: Array
    excess: Array
    diagnostics: Array
    index: NDArray[np.int64]
    """Row of the recorder's sample arrays that :attr:`evaluate` writes (if it records)."""
    _finish: Array = field(default_factory=lambda: np.zeros(2), init=False)

    def __post_init__(self) -> None:
        self._observers = [
            limit for limit in self.resolver.spec.limits if hasattr(limit, "observe")
        ]

    def load(self, q: Array) -> bool:
        """Evaluate the state at ``q`` into the buffers; False if it is singular."""
        np.copyto(self.plan.state.q, q)
        return self.evaluate() == -1

    def start(self, q0: Array) -> None:
        """Load the run's start: its verification floors are ``min(safe, value there)``."""
        if not self.load(q0):
            KinematicState.compute(self.robot, q0, self.plan.radius)  # raises the singularity
        st = self.plan.stacked
        np.minimum(st["safe"], st["values"], out=self.floor)
        self.evaluate()  # again, against the floors: the excess (and sample) of the start
        self.solver.reset()

    @property
    def broken(self) -> bool:
        """The loaded state breaks a limit by more than its tolerance."""
        return not self.excess[1] <= 1.0

    def step(self, command: Array, dt: float) -> Answer | None:
        """The common step from the loaded state: solve, integrate, load and verify the end.

        Returns the answer (the buffers then hold the end state), or None: the buffers are
        then undefined and the caller runs the reference step from the saved ``q`` and loads
        its end.
        """
        plan = self.plan
        np.copyto(plan.command, command)
        plan.dt[0] = dt
        started = time.perf_counter()
        status = self.prepare()
        prepared = time.perf_counter()
        answer = self.solver.solve(status)
        if answer is None:
            return None
        answer.solve_time = time.perf_counter() - started
        if self.solver.solves_in_prepare:  # the baseline's linear algebra ran in prepare
            answer.solver_time = prepared - started
        st, out = plan.stacked, self._finish
        finish(st["A"], st["b"], answer.qdot, plan.state.q, dt, out)
        answer.task_error = float(out[0])
        if self.verify and out[1] > JOINT_STRIDE:
            return None  # a large step: the reference checks its straight motion
        if self.evaluate() != -1 or (self.verify and self.broken):
            return None
        for limit in self._observers:
            limit.observe(answer.qdot, dt)
        return answer


def compile_step(
    robot: Robot, radius: float, resolver: Resolver, obstacles: ObstacleSet, verify: bool,
    samples: Mapping[str, np.ndarray] | None = None,
) -> CompiledStep | None:  # fmt: skip
    """The compiled step of ``resolver`` for a run, or None if a part cannot be compiled.

    ``obstacles`` are those whose clearances the diagnostics measure; ``samples`` (the
    recorder's arrays, :data:`dvqp.compiled.record.SAMPLED`), if given, receive every
    evaluated state at row :attr:`CompiledStep.index`."""
    model = CompiledModel.of(robot)
    if model is None:
        return None
    spec = resolver.spec
    plan = StepPlan(robot.n, robot.n_points, radius)
    objective = spec.objective.kernels(plan)
    tasks = task_kernels(spec, plan)
    verifiers = verifier_kernels(spec, plan)
    near = plan.proximity(obstacles)
    if objective is None or tasks is None or verifiers is None or near is None:
        return None
    solver = _solver(resolver, plan)
    if solver is None:
        return None
    pairs, st, s = plan.self_pairs(), plan.stacked, plan.state
    floor, excess, diagnostics = np.zeros_like(st["values"]), np.zeros(2), np.zeros(4)
    evaluate = [
        model.kernel(plan),
        Kernel(clear, (plan.objective_value, plan.objective_gradient)),
        *plan.geometry, *objective, *verifiers,
        Kernel(worst_excess, (st["values"], floor, st["tolerance"], excess)),
        Kernel(summary, (s.origins, s.axes, pairs.distance, near.point_distance,
                         near.link_distance, diagnostics)),
    ]  # fmt: skip
    index = np.zeros(1, dtype=np.int64)
    if samples is not None:
        value = plan.objective_value
        evaluate.append(sample_kernel(index, samples, s, value, excess, diagnostics))
    prepare = [plan.bind(k) for k in tasks] + solver.kernels
    return CompiledStep(robot, plan, resolver, verify, solver,
                        fuse([plan.bind(k) for k in evaluate]), fuse(prepare), floor, excess,
                        diagnostics, index)  # fmt: skip


def _solver(resolver: Resolver, plan: StepPlan) -> CompiledQP | CompiledPinv | None:
    spec = resolver.spec
    gain = spec.objective.gain
    if not ownership.exact(spec, StepSpec) or not ownership.exact(spec.objective, Objective):
        return None
    if ownership.exact(resolver, PseudoinverseResolver):
        plan.finalize()
        return CompiledPinv(spec, plan, resolver.damping, gain)
    if ownership.exact(resolver, QPResolver):
        rows = limit_kernels(spec, plan)
        if rows is None:
            return None
        return CompiledQP(spec, plan, resolver.factory, rows, gain)
    return None
