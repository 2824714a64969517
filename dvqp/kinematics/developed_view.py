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


def heading_row(
    origin: NDArray[np.float64], axis: NDArray[np.float64], frame_jacobian: NDArray[np.float64]
) -> tuple[float, NDArray[np.float64]]:
    """Heading ``α`` (rad) of a frame and its Jacobian row ``∂α/∂Q``, shape (n,).

    With ``ż = ω × z``: ``∂α/∂Q = ∂α/∂O·J_v + ∂α/∂z·(−S(z)·J_ω) = ∂α/∂O·J_v + (z × ∂α/∂z)·J_ω``.

    Parameters
    ----------
    origin, axis
        Frame origin (m) and unit z axis, shape (3,) each, base frame.
    frame_jacobian
        The frame's ``[J_v; J_ω]`` in the base orientation (LOCAL_WORLD_ALIGNED), (6, n).
    """
    ox, oy, _ = origin.tolist()
    zx, zy, zz = axis.tolist()
    alpha, (dox, doy, dzx, dzy, dzz) = heading_terms(ox, oy, zx, zy, zz)
    weights = np.array(
        [dox, doy, 0.0, zy * dzz - zz * dzy, zz * dzx - zx * dzz, zx * dzy - zy * dzx]
    )
    return alpha, weights @ frame_jacobian
