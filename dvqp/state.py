"""One kinematics update per step: the state every other computation reads.

:func:`KinematicState.compute` runs Pinocchio's forward kinematics and frame Jacobians once
for the body points and the tool, maps them to the developed view, and freezes the result
(all arrays are read-only). The objective, the baseline and the QP constraints only read it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike, NDArray

from dvqp import _validate
from dvqp import developed_view as dv
from dvqp.robot import Robot

_LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


@dataclass(frozen=True)
class KinematicState:
    """Kinematics of one configuration in Cartesian and developed-view coordinates.

    Attributes
    ----------
    q : ndarray, shape (n,)
        Joint configuration, rad.
    radius : float
        Pipe radius, m.
    origins : ndarray, shape (k+1, 3)
        Frame origins of the k body points then the tool, m, base frame.
    axes : ndarray, shape (k+1, 3)
        Unit z axes of the same frames.
    points : ndarray, shape (k, 3)
        Body points in DV, ``[l, z, h]`` (m).
    point_jacobians : ndarray, shape (k, 3, n)
        ``∂[l, z, h]/∂Q`` of each body point, m/rad.
    tool : ndarray, shape (4,)
        Tool DV coordinates ``[l, z, h, α]`` (m, m, m, rad).
    tool_jacobian : ndarray, shape (4, n)
        The DV task Jacobian ``J̄(Q)``.
    """

    q: NDArray[np.float64]
    radius: float
    origins: NDArray[np.float64]
    axes: NDArray[np.float64]
    points: NDArray[np.float64]
    point_jacobians: NDArray[np.float64]
    tool: NDArray[np.float64]
    tool_jacobian: NDArray[np.float64]

    @property
    def n(self) -> int:
        """Number of joints."""
        return int(self.q.shape[0])

    @classmethod
    def compute(cls, robot: Robot, q: ArrayLike, radius: float) -> KinematicState:
        """Run forward kinematics and frame Jacobians once and map them to the DV.

        Parameters
        ----------
        robot
            The manipulator (its Pinocchio ``data`` is used as scratch space).
        q
            Joint configuration, rad, shape (n,).
        radius
            Pipe radius, m, > 0.

        Raises
        ------
        ShapeError
            ``q`` has the wrong length.
        SingularConfigurationError
            A point or the tool lies on the pipe axis.
        """
        qv = robot.check_q(q).copy()
        model, data = robot.model, robot.data
        pin.computeJointJacobians(model, data, qv)
        pin.updateFramePlacements(model, data)
        ids = robot.frame_ids
        m = len(ids)
        origins = np.empty((m, 3))
        axes = np.empty((m, 3))
        jac = np.empty((m, 6, qv.shape[0]))
        for i, fid in enumerate(ids):
            placement = data.oMf[fid]
            origins[i] = placement.translation
            axes[i] = placement.rotation[:, 2]
            jac[i] = pin.getFrameJacobian(model, data, fid, _LWA)
        pos = dv.position(origins, radius)
        dpos = dv.position_jacobian(origins, radius)
        lin = dpos @ jac[:, :3, :]  # (m, 3, n)
        tool_o, tool_z = origins[-1], axes[-1]
        # ż = ω × z = −S(z)·ω: heading row is ∂α/∂O·Jv + ∂α/∂z·(−S(z)·Jω)
        dalpha = dv.heading_gradient(tool_o, tool_z)
        heading_row = dalpha[:3] @ jac[-1, :3] - dalpha[3:] @ dv.skew(tool_z) @ jac[-1, 3:]
        tool = np.append(pos[-1], dv.heading(tool_o, tool_z))
        tool_jac = np.vstack([lin[-1], heading_row[None, :]])
        ro = _validate.readonly
        return cls(
            q=ro(qv),
            radius=float(radius),
            origins=ro(origins),
            axes=ro(axes),
            points=ro(pos[:-1].copy()),
            point_jacobians=ro(lin[:-1].copy()),
            tool=ro(tool),
            tool_jacobian=ro(tool_jac),
        )
