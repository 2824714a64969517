"""Joint position limits as velocity bounds one step ahead."""

from __future__ import annotations

import numpy as np

from dvqp.compiled.plan import Kernel, StepPlan
from dvqp.kinematics.robot import Robot
from dvqp.kinematics.state import KinematicState
from dvqp.limits.bounds_kernels import joint_position_bounds, joint_room_values
from dvqp.limits.excess import Excess
from dvqp.limits.limit import Bounds


class JointPositionLimit:
    """``(q_min − q)/dt ≤ Q̇ ≤ (q_max − q)/dt`` (rad/s), from the robot's limits.

    Infinite limits give infinite bounds. A joint already past a limit (which the planner never
    produces from a valid start) may not move further out: its bound is clipped at 0.

    Parameters
    ----------
    robot
        Its ``q_min`` and ``q_max`` (rad), shape (n,).
    """

    name = "joint_position"
    tolerance = 1e-6
    """rad: how far past a limit an integrated step may end (the QP holds it exactly)."""

    def __init__(self, robot: Robot) -> None:
        self.q_min = robot.q_min
        self.q_max = robot.q_max

    def compute(self, state: KinematicState, dt: float) -> Bounds:
        """The box at ``state.q``, shape (n,) each."""
        lb = np.minimum((self.q_min - state.q) / dt, 0.0)
        ub = np.maximum((self.q_max - state.q) / dt, 0.0)
        return Bounds(lb, ub)

    def excess(self, start: KinematicState, state: KinematicState) -> Excess:
        """How far ``state.q`` is past the limits (or past ``start.q`` if that was out)."""
        upper = np.maximum(self.q_max, start.q)
        lower = np.minimum(self.q_min, start.q)
        over = np.maximum(state.q - upper, lower - state.q)
        i = int(np.argmax(over))
        bound = upper[i] if state.q[i] > upper[i] else lower[i]
        label = f"joint{i + 1}" if over[i] > 0.0 else ""
        return Excess(
            float(over[i]), self.tolerance, label, "joint position", "rad", float(state.q[i]),
            float(bound),
        )  # fmt: skip

    def kernel(self, plan: StepPlan) -> Kernel:
        """The box at ``plan.state.q``, intersected into ``plan.lb``, ``plan.ub``."""
        args = (plan.state.q, self.q_min, self.q_max, plan.dt, plan.lb, plan.ub)
        return Kernel(joint_position_bounds, args)

    def verifier(self, plan: StepPlan) -> Kernel:
        """``[q_max − q, q − q_min]``, rad, shape (2n,), safe value 0 (``inf`` where a joint
        is unlimited: never the worst)."""
        slot = plan.verified(self, 2 * plan.n, 0.0, self.tolerance)
        return Kernel(joint_room_values, (plan.state.q, self.q_min, self.q_max, slot))
