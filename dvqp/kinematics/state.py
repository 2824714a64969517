"""One kinematics update per step: the state every other computation reads.

:func:`KinematicState.compute` runs Pinocchio's forward kinematics and frame Jacobians once
for the body points and the tool, maps them to the developed view, and freezes the result
(all arrays are read-only). The objective, the baseline and the QP constraints only read it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike, NDArray

from dvqp import _validate
from dvqp.kinematics import developed_view as dv
from dvqp.kinematics.robot import Robot

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
        Unit z axes of the same frames (the last one is the probe's axis).
    frame_jacobians : ndarray, shape (k+1, 6, n)
        ``[J_v; J_ω]`` of the same frames in the base orientation (Pinocchio's
        LOCAL_WORLD_ALIGNED): ``ȯ = J_v Q̇``, ``ω = J_ω Q̇``; a user task reads these.
    guarded : ndarray, shape (k+1, 3)
        DV positions ``[l, z, h]`` (m) of every guarded point: the k body points, then the
        probe (the tool point). Consecutive points bound the guarded links: the k−1 body links,
        then the probe holder (last body point to the tool).
    guarded_jacobians : ndarray, shape (k+1, 3, n)
        ``∂[l, z, h]/∂Q`` of the same points, m/rad.
    points : ndarray, shape (k, 3)
        Body points in DV, ``[l, z, h]`` (m): ``guarded[:-1]``.
    point_jacobians : ndarray, shape (k, 3, n)
        ``∂[l, z, h]/∂Q`` of each body point, m/rad: ``guarded_jacobians[:-1]``.
    tool : ndarray, shape (4,)
        Tool DV coordinates ``[l, z, h, α]`` (m, m, m, rad).
    tool_jacobian : ndarray, shape (4, n)
        The DV task Jacobian ``J̄(Q)``.
    cache : dict
        Quantities derived from this state once and shared: the proximity to an obstacle
        set (:func:`dvqp.geometry.proximity`), an objective's value and gradient.
    """

    q: NDArray[np.float64]
    radius: float
    origins: NDArray[np.float64]
    axes: NDArray[np.float64]
    frame_jacobians: NDArray[np.float64]
    guarded: NDArray[np.float64]
    guarded_jacobians: NDArray[np.float64]
    points: NDArray[np.float64]
    point_jacobians: NDArray[np.float64]
    tool: NDArray[np.float64]
    tool_jacobian: NDArray[np.float64]
    cache: dict[Any, Any] = field(default_factory=dict, repr=False, compare=False)

    @property
    def n(self) -> int:
        """Number of joints."""
        return int(self.q.shape[0])

    @property
    def k(self) -> int:
        """Number of body points."""
        return int(self.points.shape[0])

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
        qv = robot.check_q(q)  # a copy
        model, data = robot.model, robot.data
        pin.computeJointJacobians(model, data, qv)
        pin.updateFramePlacements(model, data)
        ids = robot.frame_ids
        frames = np.array([data.oMf[i].homogeneous for i in ids])  # (m, 4, 4)
        jac = np.array([pin.getFrameJacobian(model, data, i, _LWA) for i in ids])  # (m, 6, n)
        origins = frames[:, :3, 3]
        axes = frames[:, :3, 2]
        r = _validate.positive("radius", radius)
        pos, lin = dv.position_and_rows(origins, jac[:, :3, :], r, robot.frame_names)
        alpha, alpha_row = dv.heading_row(origins[-1], axes[-1], jac[-1])
        tool = np.empty(4)
        tool[:3] = pos[-1]
        tool[3] = alpha
        tool_jac = np.empty((4, jac.shape[2]))
        tool_jac[:3] = lin[-1]
        tool_jac[3] = alpha_row
        ro = _validate.readonly
        pos, lin = ro(pos), ro(lin)
        return cls(
            q=ro(qv),
            radius=float(radius),
            origins=ro(origins),
            axes=ro(axes),
            frame_jacobians=ro(jac),
            guarded=pos,
            guarded_jacobians=lin,
            points=pos[:-1],
            point_jacobians=lin[:-1],
            tool=ro(tool),
            tool_jacobian=ro(tool_jac),
        )
