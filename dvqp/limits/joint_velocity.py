"""Joint velocity limits."""

from __future__ import annotations

from dvqp.compiled.plan import Kernel, StepPlan
from dvqp.kinematics.robot import Robot
from dvqp.kinematics.state import KinematicState
from dvqp.limits.bounds_kernels import joint_velocity_bounds
from dvqp.limits.limit import Bounds


class JointVelocityLimit:
    """``−q̇_max ≤ Q̇ ≤ q̇_max`` (rad/s), from the robot's ``qd_max``, shape (n,).

    A bound of the QP held exactly by every accepted solution (the solution check recomputes
    it), so it needs no exact verification of the integrated motion.
    """

    name = "joint_velocity"

    def __init__(self, robot: Robot) -> None:
        self.qd_max = robot.qd_max

    def compute(self, state: KinematicState, dt: float) -> Bounds:
        """The constant box (``state`` and ``dt`` are not used)."""
        return Bounds(-self.qd_max, self.qd_max.copy())

    def kernel(self, plan: StepPlan) -> Kernel:
        """The constant box, intersected into ``plan.lb``, ``plan.ub``."""
        return Kernel(joint_velocity_bounds, (self.qd_max, plan.lb, plan.ub))
