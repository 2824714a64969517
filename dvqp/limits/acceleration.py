"""Joint acceleration limits, with the braking distance that keeps the position limits reachable.

``|q̈| ≤ q̈_max`` per joint becomes a box on this step's ``Q̇`` around the previous step's
``Q̇_prev``: ``Q̇_prev − q̈_max dt ≤ Q̇ ≤ Q̇_prev + q̈_max dt``. So that a joint can always stop
before its position limit, the box is also capped by the fastest velocity from which the joint
still stops in time: moving ``Q̇ dt`` this step, then braking at ``q̈_max`` over
``Q̇²/(2 q̈_max)``, must end within the limit, ``Q̇ dt + Q̇²/(2a) ≤ D`` with ``D`` the distance
left, i.e. ``Q̇ ≤ −a dt + sqrt(a² dt² + 2 a D)`` (and the mirror bound toward ``q_min``).

The limit remembers the velocity of the last step it was told about: the resolution loop
calls :meth:`AccelerationLimit.observe` after each accepted (sub)step and
:meth:`AccelerationLimit.reset` at the start of a run (at rest). Both write into the same
array for the limit's whole life, which the compiled kernel (:meth:`AccelerationLimit.kernel`)
reads.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from dvqp import _validate
from dvqp.compiled.plan import Kernel, StepPlan
from dvqp.errors import ParameterError
from dvqp.kinematics.robot import Robot
from dvqp.kinematics.state import KinematicState
from dvqp.limits.bounds_kernels import acceleration_bounds
from dvqp.limits.limit import Bounds

DEFAULT_QDD_MAX = 10.0
"""rad/s²: the default joint acceleration limit of the NDT arm's drives."""


class AccelerationLimit:
    """``|Q̇ − Q̇_prev| ≤ q̈_max dt`` and the braking bound toward the position limits.

    Parameters
    ----------
    robot
        Its ``q_min``, ``q_max`` (rad) for the braking bound; shape (n,).
    qdd_max
        ``q̈_max``, rad/s², scalar or shape (n,), > 0.
    """

    name = "acceleration"

    def __init__(self, robot: Robot, qdd_max: ArrayLike = DEFAULT_QDD_MAX) -> None:
        a = _validate.broadcast("qdd_max", qdd_max, robot.n)
        if np.any(a <= 0):
            raise ParameterError("qdd_max", "must be > 0 for every joint")
        self.qdd_max = _validate.readonly(a)
        self.q_min, self.q_max = robot.q_min, robot.q_max
        self._previous = np.zeros(robot.n)

    @property
    def previous(self) -> NDArray[np.float64]:
        """The last observed joint velocity, rad/s, shape (n,).

        The array is live: the same object for the limit's whole life, overwritten in place by
        :meth:`observe` and :meth:`reset` (copy it to keep a value)."""
        return self._previous

    def reset(self) -> None:
        """A run starts at rest (in place)."""
        self._previous.fill(0.0)

    def observe(self, qdot: NDArray[np.float64], dt: float) -> None:
        """The joint velocity (rad/s, shape (n,)) applied over the step just taken, copied in
        place."""
        np.copyto(self._previous, qdot)

    def compute(self, state: KinematicState, dt: float) -> Bounds:
        """The box of this step, rad/s, shape (n,) each."""
        a = self.qdd_max
        lb = self._previous - a * dt
        ub = self._previous + a * dt
        ub = np.minimum(ub, _braking(a, dt, self.q_max - state.q))
        lb = np.maximum(lb, -_braking(a, dt, state.q - self.q_min))
        # a joint that cannot brake in time any more keeps its position limit, not this bound
        return Bounds(np.minimum(lb, ub), ub)

    def kernel(self, plan: StepPlan) -> Kernel:
        """The box at ``plan.state.q`` around :attr:`previous` (read live at every call),
        intersected into ``plan.lb``, ``plan.ub``."""
        args = (plan.state.q, self.q_min, self.q_max, self.qdd_max, self._previous, plan.dt,
                plan.lb, plan.ub)  # fmt: skip
        return Kernel(acceleration_bounds, args)


def _braking(a: NDArray[np.float64], dt: float, room: NDArray[np.float64]) -> NDArray[np.float64]:
    """Fastest velocity toward a limit ``room`` (rad) away that still stops before it, rad/s."""
    # an unlimited joint: room = inf gives inf (no bound), without warnings
    return -a * dt + np.sqrt((a * dt) ** 2 + 2.0 * a * np.maximum(room, 0.0))
