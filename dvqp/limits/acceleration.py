"""Joint acceleration limits, with the braking distance that keeps the position limits reachable.

``|q̈| ≤ q̈_max`` per joint becomes a box on this step's ``Q̇`` around the previous step's
``Q̇_prev``: ``Q̇_prev − q̈_max dt ≤ Q̇ ≤ Q̇_prev + q̈_max dt``. So that a joint can always stop
before its position limit, the box is also capped by the fastest velocity from which the joint
still stops in time: moving ``Q̇ dt`` this step, then braking at ``q̈_max`` over
``Q̇²/(2 q̈_max)``, must end within the limit, ``Q̇ dt + Q̇²/(2a) ≤ D`` with ``D`` the distance
left, i.e. ``Q̇ ≤ −a dt + sqrt(a² dt² + 2 a D)`` (and the mirror bound toward ``q_min``).

The limit remembers the velocity of each accepted (sub)step (:meth:`AccelerationLimit.observe`;
at rest after :meth:`AccelerationLimit.reset`) in one array, which the compiled step reads.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from dvqp import _validate
from dvqp.errors import ParameterError
from dvqp.kinematics.robot import Robot
from dvqp.kinematics.state import KinematicState
from dvqp.limits.limit import Bounds, Limit, SceneLimits
from dvqp.workspace.wiring import StepWiring, overrides
from solvers.jit import njit

DEFAULT_QDD_MAX = 10.0
"""rad/s²: the default joint acceleration limit of the NDT arm's drives."""

Array = NDArray[np.float64]


class AccelerationLimit(Limit):
    """``|Q̇ − Q̇_prev| ≤ q̈_max dt`` and the braking bound toward the position limits
    (compiled: :func:`acceleration_bounds`; at most one in a step).

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

    @classmethod
    def from_scene(cls, scene: SceneLimits) -> AccelerationLimit:
        """The arm's limits and the scene's ``[robot] qdd_max``."""
        return cls(scene.robot, scene.qdd_max)

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

    def observed_into(self) -> NDArray[np.float64] | None:
        """:attr:`previous`: :meth:`observe` copies the velocity there, and a run's compiled
        loop may do the same (None if a subclass observes otherwise)."""
        return None if overrides(self, AccelerationLimit, "observe") else self._previous

    def compute(self, state: KinematicState, dt: float) -> Bounds:
        """The box :func:`acceleration_bounds` intersects at ``state`` for a step of ``dt`` s
        (after the velocity last observed)."""
        lb, ub = np.full(state.n, -np.inf), np.full(state.n, np.inf)
        q, a, dt = np.asarray(state.q), self.qdd_max, float(dt)
        acceleration_bounds(q, self.q_min, self.q_max, a, self._previous, dt, lb, ub)
        return Bounds(lb, ub)

    def join(self, step: StepWiring) -> None:
        """Be the compiled step's acceleration box (the last to join, if several)."""
        if overrides(self, AccelerationLimit, "compute", "kernel"):
            return super().join(step)
        step.acceleration = self
        return None


@njit(inline="always")
def _braking(a: float, dt: float, room: float) -> float:
    """Fastest velocity toward a limit ``room`` (rad) away that still stops before it, rad/s:
    ``Q̇ dt + Q̇²/(2a) ≤ room`` (an unlimited side, ``room = inf``, gives inf)."""
    return -a * dt + math.sqrt((a * dt) ** 2 + 2.0 * a * max(room, 0.0))


@njit(separate=True)
def acceleration_bounds(
    q: Array,
    q_min: Array,
    q_max: Array,
    qdd_max: Array,
    previous: Array,
    dt: float,
    lb: Array,
    ub: Array,
) -> None:
    """The box ``|Q̇ − Q̇_prev| ≤ q̈_max dt`` capped by the braking bounds, intersected into
    ``lb``, ``ub`` in place. A joint that cannot brake in time any more keeps its position
    limit, not this bound (``lb = min(low, high)``)."""
    for i in range(q.shape[0]):
        a = qdd_max[i]
        low, high = previous[i] - a * dt, previous[i] + a * dt
        high = min(high, _braking(a, dt, q_max[i] - q[i]))
        low = max(low, -_braking(a, dt, q[i] - q_min[i]))
        lb[i] = max(lb[i], min(low, high))
        ub[i] = min(ub[i], high)
