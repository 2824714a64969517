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


def _rho(origins: NDArray[np.float64]) -> NDArray[np.float64]:
    rho = np.hypot(origins[:, 0], origins[:, 1])
    if np.any(rho < RHO_MIN):
        i = int(np.argmin(rho))
        raise SingularConfigurationError(f"point {i} lies on the pipe axis (rho = {rho[i]:.3g} m)")
    return rho


def position(origins: ArrayLike, radius: float) -> NDArray[np.float64]:
    """DV position ``[l, z, h]`` of k points.

    Parameters
    ----------
    origins
        Cartesian positions, m, shape (k, 3).
    radius
        Pipe radius, m.

    Returns
    -------
    ndarray, shape (k, 3)
    """
    o = np.asarray(origins, dtype=np.float64)
    rho = _rho(o)
    return np.column_stack([radius * np.arctan2(o[:, 1], o[:, 0]), o[:, 2], rho - radius])


def position_jacobian(origins: ArrayLike, radius: float) -> NDArray[np.float64]:
    """``∂[l, z, h]/∂O`` of k points, shape (k, 3, 3)."""
    o = np.asarray(origins, dtype=np.float64)
    rho = _rho(o)
    k = o.shape[0]
    out = np.zeros((k, 3, 3))
    out[:, 0, 0] = -radius * o[:, 1] / rho**2
    out[:, 0, 1] = radius * o[:, 0] / rho**2
    out[:, 1, 2] = 1.0
    out[:, 2, 0] = o[:, 0] / rho
    out[:, 2, 1] = o[:, 1] / rho
    return out


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
