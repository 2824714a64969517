"""Denavit–Hartenberg tables: the rows the arm is built from (:meth:`dvqp.Robot.from_dh`).

Standard DH: ``T_i^{i-1} = Rz(θ_i) · Tz(d_i) · Tx(a_i) · Rx(α_i)``; the joint's rotation
``Rz(θ_i)`` is Pinocchio's revolute joint, the rest the fixed part of the row.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from dvqp import _validate
from dvqp.errors import ParameterError, ShapeError


@dataclass(frozen=True)
class DHRow:
    """One row of a standard DH table (the joint variable θ is the revolute angle).

    Attributes
    ----------
    d : float
        Offset along the previous z axis, m.
    a : float
        Length along the new x axis, m.
    alpha : float
        Twist about the new x axis, rad.
    theta_offset : float
        Constant added to the joint angle, rad.
    """

    d: float
    a: float
    alpha: float
    theta_offset: float = 0.0


def fixed_part(row: DHRow) -> NDArray[np.float64]:
    """Homogeneous transform ``Tz(d) · Tx(a) · Rx(α)`` of a DH row, shape (4, 4)."""
    ca, sa = np.cos(row.alpha), np.sin(row.alpha)
    return np.array(
        [[1.0, 0.0, 0.0, row.a], [0.0, ca, -sa, 0.0], [0.0, sa, ca, row.d], [0.0, 0.0, 0.0, 1.0]]
    )


def ndt13_table(link_lengths: ArrayLike) -> tuple[list[DHRow], NDArray[np.float64]]:
    """DH table and tool transform of the paper's 13-DOF NDT manipulator (Table I, eq. 2).

    Parameters
    ----------
    link_lengths
        ``[L1, …, L7]``, m, shape (7,). ``L1`` is the rail radius (``d_2``), ``L7`` the
        offset of the probe holder from the last joint.

    Returns
    -------
    table : list of DHRow
        The 13 rows.
    tool : ndarray, shape (4, 4)
        ``T_e^13``.
    """
    lengths = _validate.vector("link_lengths", link_lengths, 7)
    if np.any(lengths < 0):
        raise ParameterError("link_lengths", "must be >= 0")
    l1, l2, l3, l4, l5, l6, l7 = lengths
    p, m = 0.5 * np.pi, -0.5 * np.pi
    table = [
        DHRow(0.0, 0.0, p),
        DHRow(l1, 0.0, m),
        DHRow(l2, 0.0, m),
        DHRow(0.0, 0.0, p),
        DHRow(l3, 0.0, m),
        DHRow(0.0, 0.0, p),
        DHRow(l4, 0.0, p),
        DHRow(0.0, 0.0, p),
        DHRow(0.0, l5, m),
        DHRow(0.0, 0.0, p),
        DHRow(0.0, l6, m),
        DHRow(0.0, 0.0, p),
        DHRow(0.0, 0.0, 0.0),
    ]
    tool = np.array(
        [[0.0, 0.0, 1.0, l7], [1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]]
    )
    return table, tool


def check_transform(name: str, t: ArrayLike) -> NDArray[np.float64]:
    """Validate a homogeneous transform: shape (4, 4), orthonormal rotation, last row 0 0 0 1."""
    arr = np.asarray(t, dtype=np.float64)
    if arr.shape != (4, 4):
        raise ShapeError(name, (4, 4), arr.shape)
    rot = arr[:3, :3]
    if not np.all(np.isfinite(arr)) or not np.allclose(rot @ rot.T, np.eye(3), atol=1e-9):
        raise ParameterError(name, "rotation part must be orthonormal")
    if not np.allclose(arr[3], [0.0, 0.0, 0.0, 1.0]) or np.linalg.det(rot) < 0:
        raise ParameterError(name, "must be a proper homogeneous transform")
    return arr
