"""Compiled (numba) rows and verification values of the damper limits.

Every damper row is ``G = −∂d/∂Q``, ``h = rhs(d)`` with the right-hand side of
:func:`damper_value` (the scalar twin of :func:`dvqp.limits.damper.damper_rhs`). A damper's
parameters travel as one tuple ``params = (d_safe, γ, δ, a)``: safe value (m, or the
distance's unit), gain, depth (the verification tolerance) and deceleration (``inf``: no cap).
The step ``dt`` (s) is read from the plan's one-element array at every call. A row that the
reference path would not emit is written as ``G = 0``, ``h = +inf``.

The kernels read :class:`~dvqp.compiled.plan.StateBuffers` (``guarded``,
``guarded_jacobians``, ``origins``, ``axes``, ``frame_jacobians``) and
:class:`~dvqp.compiled.plan.ProximityBuffers`; they write the rows ``G`` (p, n), ``h`` (p,) or
the verification ``values`` (p,) in place.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import NDArray

Array = NDArray[np.float64]
Params = tuple[float, float, float, float]

_SIN_FLOOR = 1e-9
"""As :data:`dvqp.limits.tilt._SIN_FLOOR`: the smallest ``sin θ`` a tilt gradient divides by."""


@njit(cache=True)
def damper_value(
    distance: float, safe: float, gain: float, dt: float, depth: float, deceleration: float
) -> float:
    """The damper's right-hand side for one distance, m/s: the rules of
    :func:`dvqp.limits.damper.damper_rhs`, bit for bit.

    Parameters
    ----------
    distance, safe
        ``d`` and ``d_safe``, m.
    gain
        ``γ`` in (0, 1].
    dt
        Step, s.
    depth
        ``δ``, m: below ``d_safe − δ`` the right-hand side is 0.
    deceleration
        ``a``, m/s² (``inf``: no braking cap).
    """
    room = distance - safe
    rhs = 0.0 if room < -depth else gain / dt * room
    if math.isinf(deceleration):
        return rhs
    low, high = -deceleration * dt, math.sqrt(2.0 * deceleration * max(room, 0.0))
    return min(max(rhs, low), high)


@njit(cache=True)
def _rhs(distance: float, params: Params, dt: float) -> float:
    """:func:`damper_value` with the damper's parameter tuple."""
    return damper_value(distance, params[0], params[1], dt, params[2], params[3])


@njit(cache=True)
def _inactive(G: Array, h: Array, row: int) -> None:
    """Write row ``row`` as ``0 · Q̇ ≤ +inf``."""
    G[row, :] = 0.0
    h[row] = np.inf


@njit(cache=True)
def height_rows(
    guarded: Array, guarded_jacobians: Array, first: int, params: Params, dt: Array,
    G: Array, h: Array,
) -> None:  # fmt: skip
    """Rows ``h_p ≥ d_safe`` of the guarded points ``first .. first + len(h) − 1``."""
    step = dt[0]
    for m in range(h.shape[0]):
        p = first + m
        h[m] = _rhs(guarded[p, 2], params, step)
        for c in range(G.shape[1]):
            G[m, c] = -guarded_jacobians[p, 2, c]


@njit(cache=True)
def height_values(guarded: Array, first: int, values: Array) -> None:
    """The heights (m) of the guarded points ``first .. first + len(values) − 1``."""
    for m in range(values.shape[0]):
        values[m] = guarded[first + m, 2]


@njit(cache=True)
def tilt_rows(
    origins: Array, axes: Array, frame_jacobians: Array, params: Params, dt: Array,
    G: Array, h: Array,
) -> None:  # fmt: skip
    """The tilt row ``sin θ ≥ sin θ_min`` of the probe (one row), as
    :meth:`dvqp.limits.tilt.TiltLimit.distances`."""
    m = origins.shape[0] - 1
    jac = frame_jacobians[m]
    rho = math.hypot(origins[m, 0], origins[m, 1])
    rx, ry = origins[m, 0] / rho, origins[m, 1] / rho
    ax, ay, az = axes[m, 0], axes[m, 1], axes[m, 2]
    u = ax * rx + ay * ry
    c0, c1, c2 = -az * ry, az * rx, ax * ry - ay * rx
    t0, t1 = (ax - u * rx) / rho, (ay - u * ry) / rho
    d = math.sqrt(max(1.0 - u * u, 0.0))
    scale = -u / max(d, _SIN_FLOOR)
    for c in range(G.shape[1]):
        du = c0 * jac[3, c] + c1 * jac[4, c] + c2 * jac[5, c] + t0 * jac[0, c] + t1 * jac[1, c]
        G[0, c] = -(scale * du)
    h[0] = _rhs(d, params, dt[0])


@njit(cache=True)
def tilt_value(origins: Array, axes: Array, values: Array) -> None:
    """``asin(min(sin θ, 1))``, rad: the probe's tilt from radial, folded into [0, π/2]."""
    m = origins.shape[0] - 1
    ox, oy = origins[m, 0], origins[m, 1]
    u = (axes[m, 0] * ox + axes[m, 1] * oy) / math.hypot(ox, oy)
    values[0] = math.asin(min(math.sqrt(max(1.0 - u * u, 0.0)), 1.0))


@njit(cache=True)
def obstacle_rows(
    point_distance: Array, point_normal: Array, link_distance: Array, link_normal: Array,
    link_t: Array, guarded_jacobians: Array, influence: float, params: Params, dt: Array,
    G: Array, h: Array,
) -> None:  # fmt: skip
    """Rows of every (point, obstacle) then every (link, obstacle) pair, obstacle-major.

    A point row applies below the influence distance where the normal is defined; a link row
    also needs an interior closest point (``0 < t < 1``). Others are ``0 ≤ +inf``.
    """
    step = dt[0]
    count, points = point_distance.shape
    row = 0
    for j in range(count):
        for i in range(points):
            nx, ny = point_normal[j, i, 0], point_normal[j, i, 1]
            d = point_distance[j, i]
            if d < influence and (nx != 0.0 or ny != 0.0):
                for c in range(G.shape[1]):
                    G[row, c] = -nx * guarded_jacobians[i, 0, c] + -ny * guarded_jacobians[i, 1, c]
                h[row] = _rhs(d, params, step)
            else:
                _inactive(G, h, row)
            row += 1
    for j in range(count):
        for i in range(points - 1):
            nx, ny, t = link_normal[j, i, 0], link_normal[j, i, 1], link_t[j, i]
            d = link_distance[j, i]
            if d < influence and (nx != 0.0 or ny != 0.0) and 0.0 < t < 1.0:
                for c in range(G.shape[1]):
                    x = (1.0 - t) * guarded_jacobians[i, 0, c] + t * guarded_jacobians[i + 1, 0, c]
                    y = (1.0 - t) * guarded_jacobians[i, 1, c] + t * guarded_jacobians[i + 1, 1, c]
                    G[row, c] = -nx * x + -ny * y
                h[row] = _rhs(d, params, step)
            else:
                _inactive(G, h, row)
            row += 1


@njit(cache=True)
def clearance_values(point_distance: Array, link_distance: Array, values: Array) -> None:
    """Every point's then every link's clearance, m, obstacle-major (``all_distances``)."""
    row = 0
    for j in range(point_distance.shape[0]):
        for i in range(point_distance.shape[1]):
            values[row] = point_distance[j, i]
            row += 1
    for j in range(link_distance.shape[0]):
        for i in range(link_distance.shape[1]):
            values[row] = link_distance[j, i]
            row += 1


@njit(cache=True)
def copy_values(source: Array, values: Array) -> None:
    """``values[:] = source`` (e.g. the self-collision pair distances, m)."""
    for m in range(values.shape[0]):
        values[m] = source[m]
