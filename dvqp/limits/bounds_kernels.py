"""Compiled (numba) velocity boxes of the joint limits, and the joint-position verification.

A bounds kernel intersects its own box into the plan's ``lb``, ``ub`` (rad/s, shape (n,)) in
place, ``lb = max(lb, own)``, ``ub = min(ub, own)``: after the engine resets them to ``∓inf``
and runs every bounds kernel, they hold the reference's intersected box
(:func:`dvqp.resolution.qp.limit_rows`). The step ``dt`` (s) is read from the plan's
one-element array.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import NDArray

Array = NDArray[np.float64]


@njit(cache=True)
def joint_position_bounds(
    q: Array, q_min: Array, q_max: Array, dt: Array, lb: Array, ub: Array
) -> None:
    """``min((q_min − q)/dt, 0) ≤ Q̇ ≤ max((q_max − q)/dt, 0)``, intersected in place."""
    step = dt[0]
    for i in range(q.shape[0]):
        lb[i] = max(lb[i], min((q_min[i] - q[i]) / step, 0.0))
        ub[i] = min(ub[i], max((q_max[i] - q[i]) / step, 0.0))


@njit(cache=True)
def joint_velocity_bounds(qd_max: Array, lb: Array, ub: Array) -> None:
    """``−q̇_max ≤ Q̇ ≤ q̇_max``, intersected in place."""
    for i in range(qd_max.shape[0]):
        lb[i] = max(lb[i], -qd_max[i])
        ub[i] = min(ub[i], qd_max[i])


@njit(cache=True)
def _braking(a: float, dt: float, room: float) -> float:
    """Fastest velocity toward a limit ``room`` (rad) away that still stops before it, rad/s
    (as :func:`dvqp.limits.acceleration._braking`)."""
    return -a * dt + math.sqrt((a * dt) ** 2 + 2.0 * a * max(room, 0.0))


@njit(cache=True)
def acceleration_bounds(
    q: Array, q_min: Array, q_max: Array, qdd_max: Array, previous: Array, dt: Array,
    lb: Array, ub: Array,
) -> None:  # fmt: skip
    """The box ``|Q̇ − Q̇_prev| ≤ q̈_max dt`` capped by the braking bounds, intersected in
    place (as :meth:`dvqp.limits.acceleration.AccelerationLimit.compute`)."""
    step = dt[0]
    for i in range(q.shape[0]):
        a = qdd_max[i]
        low, high = previous[i] - a * step, previous[i] + a * step
        high = min(high, _braking(a, step, q_max[i] - q[i]))
        low = max(low, -_braking(a, step, q[i] - q_min[i]))
        lb[i] = max(lb[i], min(low, high))
        ub[i] = min(ub[i], high)


@njit(cache=True)
def joint_room_values(q: Array, q_min: Array, q_max: Array, values: Array) -> None:
    """``[q_max − q, q − q_min]``, rad, shape (2n,): the joint position verification values
    (``inf`` for an unlimited side)."""
    n = q.shape[0]
    for i in range(n):
        values[i] = q_max[i] - q[i]
        values[n + i] = q[i] - q_min[i]
