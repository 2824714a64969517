"""Joint position and velocity limits: boxes on this step's joint velocities."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from dvqp.kinematics.robot import Robot
from dvqp.kinematics.state import KinematicState
from dvqp.limits.limit import Bounds, Limit, SceneLimits
from dvqp.workspace.wiring import StepWiring, overrides
from solvers.jit import njit

Array = NDArray[np.float64]


class JointPositionLimit(Limit):
    """``(q_min − q)/dt ≤ Q̇ ≤ (q_max − q)/dt`` (rad/s), from the robot's limits (compiled:
    :func:`position_bounds`; verified exactly: :func:`joint_room`).

    Infinite limits give infinite bounds. A joint already past a limit (which the planner never
    produces from a valid start) may not move further out: its bound is clipped at 0.

    Parameters
    ----------
    robot
        Its ``q_min`` and ``q_max`` (rad), shape (n,).
    """

    name = "joint_position"
    quantity, unit = "joint room", "rad"
    tolerance = 1e-6
    """rad: how far past a limit an integrated step may end (the QP holds it exactly)."""

    def __init__(self, robot: Robot) -> None:
        self.q_min = robot.q_min
        self.q_max = robot.q_max

    @classmethod
    def from_scene(cls, scene: SceneLimits) -> JointPositionLimit:
        """The arm's own position limits."""
        return cls(scene.robot)

    def compute(self, state: KinematicState, dt: float) -> Bounds:
        """The box :func:`position_bounds` intersects at ``state`` for a step of ``dt`` s."""
        lb, ub = np.full(state.n, -np.inf), np.full(state.n, np.inf)
        position_bounds(np.asarray(state.q), self.q_min, self.q_max, float(dt), lb, ub)
        return Bounds(lb, ub)

    def join(self, step: StepWiring) -> None:
        """Intersect the compiled position box, and verify the joints' room exactly."""
        if overrides(self, JointPositionLimit, "compute", "kernel"):
            return super().join(step)
        step.intersect(q_min=self.q_min, q_max=self.q_max)
        if step.joint_limit is None:
            step.joint_limit = self
        return None


@njit(separate=True)
def position_bounds(q: Array, q_min: Array, q_max: Array, dt: float, lb: Array, ub: Array) -> None:
    """``min((q_min − q)/dt, 0) ≤ Q̇ ≤ max((q_max − q)/dt, 0)``, intersected into ``lb``,
    ``ub`` in place."""
    for i in range(q.shape[0]):
        lb[i] = max(lb[i], min((q_min[i] - q[i]) / dt, 0.0))
        ub[i] = min(ub[i], max((q_max[i] - q[i]) / dt, 0.0))


@njit(separate=True)
def joint_room(q: Array, q_min: Array, q_max: Array, values: Array, start: int) -> None:
    """The verified values ``[q_max − q, q − q_min]`` (rad, 2n) at ``values[start:]``
    (``inf`` on an unlimited side: never the worst)."""
    n = q.shape[0]
    for i in range(n):
        values[start + i] = q_max[i] - q[i]
        values[start + n + i] = q[i] - q_min[i]


class JointVelocityLimit(Limit):
    """``−q̇_max ≤ Q̇ ≤ q̇_max`` (rad/s), from the robot's ``qd_max``, shape (n,) (compiled:
    :func:`velocity_bounds`).

    A bound of the QP held exactly by every accepted solution (the solution check recomputes
    it), so it needs no exact verification of the integrated motion.
    """

    name = "joint_velocity"

    def __init__(self, robot: Robot) -> None:
        self.qd_max = robot.qd_max

    @classmethod
    def from_scene(cls, scene: SceneLimits) -> JointVelocityLimit:
        """The arm's own speed limits."""
        return cls(scene.robot)

    def compute(self, state: KinematicState, dt: float) -> Bounds:
        """The box :func:`velocity_bounds` intersects."""
        lb, ub = np.full(state.n, -np.inf), np.full(state.n, np.inf)
        velocity_bounds(self.qd_max, lb, ub)
        return Bounds(lb, ub)

    def join(self, step: StepWiring) -> None:
        """Intersect the compiled speed box."""
        if overrides(self, JointVelocityLimit, "compute", "kernel"):
            return super().join(step)
        step.intersect(qd_max=self.qd_max)
        return None


@njit(separate=True)
def velocity_bounds(
    qd_max: NDArray[np.float64], lb: NDArray[np.float64], ub: NDArray[np.float64]
) -> None:
    """``−q̇_max ≤ Q̇ ≤ q̇_max``, intersected into ``lb``, ``ub`` in place."""
    for i in range(qd_max.shape[0]):
        lb[i] = max(lb[i], -qd_max[i])
        ub[i] = min(ub[i], qd_max[i])
