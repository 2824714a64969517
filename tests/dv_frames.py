"""Whole-frame DV coordinates ``F(X) = [l, z, h, α]`` of one frame ``X = [O; z]``, for the tests.

The package computes these only inside :class:`dvqp.KinematicState`; the tests check the same
formulas frame by frame against finite differences and hand-worked cases.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from dvqp.kinematics.developed_view import heading_terms, position_and_rows


def position(origins: ArrayLike, radius: float) -> NDArray[np.float64]:
    """DV position ``[l, z, h]`` (m) of k points at ``origins`` (m, shape (k, 3)): (k, 3)."""
    o = np.asarray(origins, dtype=np.float64)
    return position_and_rows(o, np.zeros((o.shape[0], 3, 0)), radius)[0]


def position_jacobian(origins: ArrayLike, radius: float) -> NDArray[np.float64]:
    """``∂[l, z, h]/∂O`` of k points, shape (k, 3, 3)."""
    o = np.asarray(origins, dtype=np.float64)
    return position_and_rows(o, np.broadcast_to(np.eye(3), (o.shape[0], 3, 3)), radius)[1]


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
