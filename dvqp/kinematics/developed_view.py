"""Developed-view (DV) coordinates of points and axes around a pipe, and their derivatives.

The pipe axis is the base z axis; ``R`` is the pipe radius (m). For a point ``O`` (m) with a
unit axis ``z``, ``ρ = sqrt(Ox² + Oy²)``::

    l = R · atan2(Oy, Ox)            arc length along the circumference, m, in (−πR, πR]
    z = Oz                           position along the pipe axis, m
    h = ρ − R                        height above the pipe surface, m
    α = atan2(zz, (Ox·zy − Oy·zx)/ρ) heading of z on the surface, rad, from l toward z

All functions are vectorised over a leading axis of k points. They never return NaN: a point
on the pipe axis raises :class:`~dvqp.errors.SingularConfigurationError`; an undefined heading
(the axis radial) gives ``α = 0`` and a Jacobian row bounded by :data:`HEADING_FLOOR`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from dvqp.errors import SingularConfigurationError

RHO_MIN = 1e-9
"""Distance from the pipe axis (m) below which a point is singular."""

HEADING_FLOOR = 1e-6
"""Floor on ``c² + s²`` in the heading Jacobian (dimensionless): exact when the tool axis is
more than about 1 mrad away from radial, bounded and finite closer to it."""


def wrap(dl: ArrayLike, radius: float) -> NDArray[np.float64]:
    """Wrap arc-length differences into ``[−πR, πR)``, m, same shape as ``dl``."""
    period = 2.0 * np.pi * radius
    return np.remainder(np.asarray(dl, dtype=np.float64) + 0.5 * period, period) - 0.5 * period


def wrap_angle(da: ArrayLike) -> NDArray[np.float64]:
    """Wrap angle differences into ``[−π, π)``, rad."""
    return wrap(da, 1.0)  # a circle of radius 1 has period 2π


def unwrap(values: ArrayLike, period: float, axis: int = 0) -> NDArray[np.float64]:
    """Unwrap a sequence of wrapped values (arc length or angle) along ``axis``.

    Each increment is wrapped into ``[−period/2, period/2)`` and accumulated from the first
    value, so a path that crosses the seam ``l = ±πR`` becomes continuous.
    """
    v = np.asarray(values, dtype=np.float64)
    d = np.diff(v, axis=axis)
    d = d - period * np.floor((d + 0.5 * period) / period)
    first = np.take(v, [0], axis=axis)
    return np.concatenate([first, first + np.cumsum(d, axis=axis)], axis=axis)


def position_and_rows(
    origins: ArrayLike,
    linear_jacobians: ArrayLike,
    radius: float,
    names: Sequence[str] | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """DV positions of k points and their Jacobians through the frames' linear Jacobians.

    Parameters
    ----------
    origins
        Cartesian positions, m, shape (k, 3).
    linear_jacobians
        ``∂O/∂Q`` of each point, shape (k, 3, n) (the identity, (k, 3, 3), gives ``∂F/∂O``).
    radius
        Pipe radius, m.
    names
        Names of the points, for the error message.

    Returns
    -------
    position : ndarray, shape (k, 3)
        ``[l, z, h]``, m.
    rows : ndarray, shape (k, 3, n)
        ``∂[l, z, h]/∂O · ∂O/∂Q``, formed row by row without the 3×3 blocks.

    Raises
    ------
    SingularConfigurationError
        A point lies on the pipe axis (ρ = 0).
    """
    o = np.asarray(origins, dtype=np.float64)
    jv = np.asarray(linear_jacobians, dtype=np.float64)
    x, y = o[:, 0], o[:, 1]
    rho2 = x * x + y * y
    rho = np.sqrt(rho2)
    if not (rho >= RHO_MIN).all():
        i = int(np.argmin(rho))
        name = f"frame {names[i]!r}" if names is not None else f"point {i}"
        raise SingularConfigurationError(f"{name} lies on the pipe axis (rho = {rho[i]:.3g} m)")
    k, n = o.shape[0], jv.shape[2]
    pos = np.empty((k, 3))
    pos[:, 0] = radius * np.arctan2(y, x)
    pos[:, 1] = o[:, 2]
    pos[:, 2] = rho - radius
    jx, jy = jv[:, 0, :], jv[:, 1, :]
    rows = np.empty((k, 3, n))
    rows[:, 0] = (radius / rho2)[:, None] * (x[:, None] * jy - y[:, None] * jx)
    rows[:, 1] = jv[:, 2, :]
    rows[:, 2] = (x / rho)[:, None] * jx + (y / rho)[:, None] * jy
    return pos, rows


def position(origins: ArrayLike, radius: float) -> NDArray[np.float64]:
    """DV position ``[l, z, h]`` (m) of k points at ``origins`` (m, shape (k, 3)): (k, 3)."""
    o = np.asarray(origins, dtype=np.float64)
    return position_and_rows(o, np.zeros((o.shape[0], 3, 0)), radius)[0]


def position_jacobian(origins: ArrayLike, radius: float) -> NDArray[np.float64]:
    """``∂[l, z, h]/∂O`` of k points, shape (k, 3, 3)."""
    o = np.asarray(origins, dtype=np.float64)
    return position_and_rows(o, np.broadcast_to(np.eye(3), (o.shape[0], 3, 3)), radius)[1]


def heading_terms(
    ox: float, oy: float, zx: float, zy: float, zz: float
) -> tuple[float, tuple[float, float, float, float, float]]:
    """Heading ``α`` (rad) and its nonzero partials, in plain floats (the per-step fast path).

    Returns
    -------
    alpha : float
    partials : tuple of float
        ``(∂α/∂Ox, ∂α/∂Oy, ∂α/∂zx, ∂α/∂zy, ∂α/∂zz)``; ``∂α/∂Oz = 0``.
    """
    rho = math.hypot(ox, oy)
    if rho < RHO_MIN:
        raise SingularConfigurationError(f"frame lies on the pipe axis (rho = {rho:.3g} m)")
    c = (ox * zy - oy * zx) / rho
    s = zz
    k = 1.0 / max(c * c + s * s, HEADING_FLOOR)
    # ∂α = (c ∂s − s ∂c) / (c² + s²); s depends on zz only.
    dc_ox = zy / rho - c * ox / (rho * rho)
    dc_oy = -zx / rho - c * oy / (rho * rho)
    partials = (-s * dc_ox * k, -s * dc_oy * k, s * oy / rho * k, -s * ox / rho * k, c * k)
    return math.atan2(s, c), partials


def heading(origin: ArrayLike, axis: ArrayLike) -> float:
    """Heading ``α`` (rad) of the unit ``axis`` at ``origin`` (m) projected on the surface."""
    (ox, oy, _), (zx, zy, zz) = np.asarray(origin, float).tolist(), np.asarray(axis, float).tolist()
    return heading_terms(ox, oy, zx, zy, zz)[0]


def heading_gradient(origin: ArrayLike, axis: ArrayLike) -> NDArray[np.float64]:
    """``∂α/∂[O; z]``, shape (6,), bounded near the undefined heading (axis radial)."""
    (ox, oy, _), (zx, zy, zz) = np.asarray(origin, float).tolist(), np.asarray(axis, float).tolist()
    d = heading_terms(ox, oy, zx, zy, zz)[1]
    return np.array([d[0], d[1], 0.0, d[2], d[3], d[4]])


def coordinates(origin: ArrayLike, axis: ArrayLike, radius: float) -> NDArray[np.float64]:
    """Full DV coordinates ``F(X) = [l, z, h, α]`` of one frame, shape (4,)."""
    o = np.asarray(origin, dtype=np.float64)
    return np.append(position(o[None, :], radius)[0], heading(o, axis))


def coordinates_jacobian(origin: ArrayLike, axis: ArrayLike, radius: float) -> NDArray[np.float64]:
    """``∂F/∂X`` of one frame, ``X = [O; z]``, shape (4, 6)."""
    o = np.asarray(origin, dtype=np.float64)
    out = np.zeros((4, 6))
    out[:3, :3] = position_jacobian(o[None, :], radius)[0]
    out[3] = heading_gradient(o, axis)
    return out


def skew(v: ArrayLike) -> NDArray[np.float64]:
    """Skew-symmetric matrix ``S(v)`` with ``S(v)·u = v × u``, shape (3, 3)."""
    x, y, z = np.asarray(v, dtype=np.float64)
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
