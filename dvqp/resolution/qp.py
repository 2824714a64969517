"""The per-step QP, assembled by a pure function so every backend gets the identical problem.

Decision variable ``x = Q̇`` (rad/s), or ``x = [Q̇; s]`` when the task is relaxed by a slack
``s`` (task units: m/s, m/s, m/s, rad/s)::

    minimise    ½ Q̇ᵀ W Q̇ − gᵀ Q̇  (+ ½ ρ ‖s‖²)        g = λ ∂w/∂Q
    subject to  J̄ Q̇ = ẋ           (J̄ Q̇ − s = ẋ)      the tool's DV task
                G Q̇ ≤ h                              obstacle dampers, surface height
                lb ≤ Q̇ ≤ ub                          joint position (one step ahead) and velocity

With no active inequality its KKT conditions are exactly the weighted pseudoinverse step
(:func:`dvqp.resolution.pinv.weighted_pinv_step`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from dvqp import _validate
from dvqp.limits.limit import Bounds, Constraint
from dvqp.errors import ParameterError
from dvqp.limits import (
    DamperParameters,
    joint_position_bounds,
    joint_velocity_bounds,
    obstacle_dampers,
    surface_height,
)
from dvqp.geometry.obstacle import Obstacle
from dvqp.geometry.proximity import ObstacleSet
from dvqp.kinematics.robot import Robot
from dvqp.kinematics.state import KinematicState
from solvers import Problem

DEFAULT_TASK_WEIGHT = 1e4
"""``ρ`` of the task slack (dimensionless relative to W): large, so the task is given up last."""


@dataclass(frozen=True)
class StepConfig:
    """What stays constant between the steps of a run.

    Parameters
    ----------
    robot
        Joint limits come from here.
    obstacles
        Circles in the developed view; pass the objective's :class:`ObstacleSet` to share
        the per-step geometry with it.
    dampers
        Margin, influence, gain and minimum height of the inequality rows.
    weights
        Diagonal of ``W`` (> 0), scalar or shape (n,).
    task_weight
        ``ρ`` of the task slack in the relaxed problem, > 0.
    """

    robot: Robot
    obstacles: ObstacleSet | tuple[Obstacle, ...] = ()
    dampers: DamperParameters = field(default_factory=DamperParameters)
    weights: ArrayLike = 1.0
    task_weight: float = DEFAULT_TASK_WEIGHT

    def __post_init__(self) -> None:
        w = _validate.broadcast("weights", self.weights, self.robot.n)
        if np.any(w <= 0):
            raise ParameterError("weights", "must be > 0")
        object.__setattr__(self, "weights", _validate.readonly(w))
        if not isinstance(self.obstacles, ObstacleSet):
            object.__setattr__(self, "obstacles", ObstacleSet(self.obstacles))
        object.__setattr__(self, "task_weight", _validate.positive("task_weight", self.task_weight))

    @property
    def hessian(self) -> NDArray[np.float64]:
        """``W = diag(weights)``, shape (n, n), built once."""
        cached = self.__dict__.get("_hessian")
        if cached is None:
            cached = _validate.readonly(np.diag(np.asarray(self.weights)))
            object.__setattr__(self, "_hessian", cached)
        return cached  # type: ignore[no-any-return]

    def inequalities(self, state: KinematicState, dt: float) -> Constraint:
        """Obstacle dampers then surface-height rows at this state."""
        dampers = obstacle_dampers(state, self.obstacles, self.dampers, dt)  # type: ignore[arg-type]
        return Constraint.stack([dampers, surface_height(state, self.dampers, dt)], state.n)

    def bounds(self, state: KinematicState, dt: float) -> Bounds:
        """Joint position (one step ahead) and velocity bounds, rad/s."""
        position = joint_position_bounds(self.robot, state, dt)
        return position.intersect(joint_velocity_bounds(self.robot))


@dataclass(frozen=True)
class StepProblem:
    """The QP of one step and what its rows mean.

    Attributes
    ----------
    problem : solvers.Problem
        The QP handed to a backend.
    inequalities : Constraint
        The rows of ``problem.G`` over ``Q̇`` (their labels say what each holds).
    bounds : Bounds
        The box on ``Q̇``, rad/s.
    relaxed : bool
        The task carries a slack (the last 4 variables).
    """

    problem: Problem
    inequalities: Constraint
    bounds: Bounds
    relaxed: bool

    @property
    def labels(self) -> tuple[str, ...]:
        """One label per inequality row, e.g. ``"link2/obstacle1"``."""
        return self.inequalities.labels


def build_step_qp(
    config: StepConfig,
    state: KinematicState,
    gradient: NDArray[np.float64],
    xdot: NDArray[np.float64],
    dt: float,
    *,
    relax_task: bool = False,
    limits: tuple[Constraint, Bounds] | None = None,
) -> StepProblem:
    """Assemble the QP of one step (pure: no solver involved).

    Parameters
    ----------
    config
        Constant parts (limits, obstacles, weights).
    state
        Kinematics of this step.
    gradient
        ``g = λ ∂w/∂Q``, shape (n,).
    xdot
        Commanded tool DV velocity, shape (m,) with m = 4.
    dt
        Step, s.
    relax_task
        Add the slack ``s`` on the task equality.
    limits
        The inequalities and bounds of this state if already computed (e.g. by the strict
        problem of the same step), so a relaxed retry does not assemble them again.
    """
    jac = state.tool_jacobian
    m = jac.shape[0]
    if limits is None:
        limits = (config.inequalities(state, dt), config.bounds(state, dt))
    ineq, box = limits
    if not relax_task:
        problem = Problem(
            P=config.hessian, q=-gradient, A=jac, b=xdot,
            G=ineq.G if ineq.rows else None, h=ineq.h if ineq.rows else None,
            lb=box.lb, ub=box.ub,
        )  # fmt: skip
        return StepProblem(problem, ineq, box, relaxed=False)
    inf = np.full(m, np.inf)
    problem = Problem(
        P=np.diag(np.concatenate([config.weights, np.full(m, config.task_weight)])),
        q=np.concatenate([-gradient, np.zeros(m)]),
        A=np.hstack([jac, -np.eye(m)]),
        b=xdot,
        G=np.hstack([ineq.G, np.zeros((ineq.rows, m))]) if ineq.rows else None,
        h=ineq.h if ineq.rows else None,
        lb=np.concatenate([box.lb, -inf]),
        ub=np.concatenate([box.ub, inf]),
    )
    return StepProblem(problem, ineq, box, relaxed=True)
