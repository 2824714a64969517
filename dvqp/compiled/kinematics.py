"""Compiled kinematics of a Pinocchio model: frames, frame Jacobians and the developed view.

The reference path (:meth:`dvqp.kinematics.state.KinematicState.compute`) calls Pinocchio and
copies each frame out of ``data.oMf`` (about 1 µs per frame from Python). The compiled path
evaluates the same Pinocchio *model* (its joint placements, joint axes, parents and frame
placements, read once) in one numba kernel: ``oMi = oMi[parent] · jointPlacement · M_j(q_j)``
for revolute and prismatic joints, ``oMf = oMi[parentJoint] · placement``, the frames'
LOCAL_WORLD_ALIGNED Jacobians (``ω × (p − o_j)`` per supporting revolute joint) and the DV map
of :mod:`dvqp.kinematics.developed_view`, written in place into a plan's
:class:`~dvqp.compiled.plan.StateBuffers`. Tests compare it with Pinocchio to 1e-12; a model
with any other joint type is not compiled (the run takes the reference path).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from numba import njit
from numpy.typing import NDArray

from dvqp.compiled.plan import Kernel, StepPlan
from dvqp.kinematics.developed_view import HEADING_FLOOR, RHO_MIN
from dvqp.kinematics.robot import Robot

Array = NDArray[np.float64]

_REVOLUTE, _PRISMATIC = 0, 1
_KINDS = {
    "JointModelRX": (_REVOLUTE, (1.0, 0.0, 0.0)),
    "JointModelRY": (_REVOLUTE, (0.0, 1.0, 0.0)),
    "JointModelRZ": (_REVOLUTE, (0.0, 0.0, 1.0)),
    "JointModelPX": (_PRISMATIC, (1.0, 0.0, 0.0)),
    "JointModelPY": (_PRISMATIC, (0.0, 1.0, 0.0)),
    "JointModelPZ": (_PRISMATIC, (0.0, 0.0, 1.0)),
}


@dataclass(frozen=True)
class CompiledModel:
    """A Pinocchio model's constants, as the kinematics kernel reads them.

    Attributes
    ----------
    parents : (J,) int64
        Parent of each joint (joint 0 is the universe).
    placements : (J, 4, 4)
        ``jointPlacements``.
    kinds : (J,) int64
        0 revolute, 1 prismatic (joint 0 unused).
    axes : (J, 3)
        Unit motion axis of each joint, in its own frame.
    index : (J,) int64
        ``idx_q`` of each joint.
    frame_joint : (m,) int64
        Parent joint of each guarded frame (the body points then the tool).
    frame_placement : (m, 4, 4)
        The frames' placements in their joints.
    support : (m, J) bool
        Whether joint j moves frame f.
    """

    parents: NDArray[np.int64]
    placements: Array
    kinds: NDArray[np.int64]
    axes: Array
    index: NDArray[np.int64]
    frame_joint: NDArray[np.int64]
    frame_placement: Array
    support: NDArray[np.bool_]

    @classmethod
    def of(cls, robot: Robot) -> CompiledModel | None:
        """The constants of ``robot.model``, or None if a joint is not revolute/prismatic
        about a fixed axis."""
        model = robot.model
        count = model.njoints
        kinds, axes = np.zeros(count, np.int64), np.zeros((count, 3))
        for j in range(1, count):
            joint = model.joints[j]
            found = _KINDS.get(joint.shortname())
            if found is None:
                found = _unaligned(joint)
            if found is None:
                return None
            kinds[j], axes[j] = found[0], found[1]
        frames = [model.frames[i] for i in robot.frame_ids]
        support = np.zeros((len(frames), count), dtype=np.bool_)
        for f, frame in enumerate(frames):
            j = frame.parentJoint
            while j > 0:
                support[f, j] = True
                j = model.parents[j]
        return cls(
            parents=np.array(model.parents, dtype=np.int64),
            placements=np.array([p.homogeneous for p in model.jointPlacements]),
            kinds=kinds,
            axes=axes,
            index=np.array([max(model.joints[j].idx_q, 0) for j in range(count)], np.int64),
            frame_joint=np.array([f.parentJoint for f in frames], dtype=np.int64),
            frame_placement=np.array([f.placement.homogeneous for f in frames]),
            support=support,
        )

    def kernel(self, plan: StepPlan) -> Kernel:
        """The kernel filling ``plan.state`` from ``plan.state.q``; it returns −1, or the index
        of a frame on the pipe axis (singular)."""
        s = plan.state
        count = self.parents.shape[0]
        work = np.zeros((count + 2, 4, 4))  # oMi, then two scratch transforms
        world = np.zeros((count, 3))  # the joints' motion axes in the base frame
        return Kernel(
            kinematics,
            (self.parents, self.placements, self.kinds, self.axes, self.index, self.frame_joint,
             self.frame_placement, self.support, work, world, plan.radius, s.q, s.origins, s.axes,
             s.frame_jacobians, s.guarded, s.guarded_jacobians, s.tool, s.tool_jacobian),
            checked=True,
        )  # fmt: skip


def _unaligned(joint: pin.JointModel) -> tuple[int, Array] | None:
    name = joint.shortname()
    kind = {"JointModelRevoluteUnaligned": _REVOLUTE, "JointModelPrismaticUnaligned": _PRISMATIC}
    if name not in kind:
        return None
    axis = np.array(joint.extract().axis, dtype=np.float64)
    return kind[name], axis / np.linalg.norm(axis)


@njit(cache=True)
def _motion(kind: int, axis: Array, value: float, out: Array) -> None:
    """``M_j(q_j)``: rotation by ``value`` about ``axis`` (Rodrigues) or translation along it."""
    out[:, :] = 0.0
    out[3, 3] = 1.0
    if kind == 1:
        for r in range(3):
            out[r, r] = 1.0
            out[r, 3] = axis[r] * value
        return
    c, s = math.cos(value), math.sin(value)
    x, y, z = axis[0], axis[1], axis[2]
    v = 1.0 - c
    out[0, 0], out[0, 1], out[0, 2] = c + x * x * v, x * y * v - z * s, x * z * v + y * s
    out[1, 0], out[1, 1], out[1, 2] = y * x * v + z * s, c + y * y * v, y * z * v - x * s
    out[2, 0], out[2, 1], out[2, 2] = z * x * v - y * s, z * y * v + x * s, c + z * z * v


@njit(cache=True)
def _compose(a: Array, b: Array, out: Array) -> None:
    """``out = a · b`` of two rigid transforms (4, 4), without temporaries."""
    for r in range(3):
        a0, a1, a2 = a[r, 0], a[r, 1], a[r, 2]
        for c in range(4):
            out[r, c] = a0 * b[0, c] + a1 * b[1, c] + a2 * b[2, c]
        out[r, 3] += a[r, 3]
    out[3, 0], out[3, 1], out[3, 2], out[3, 3] = 0.0, 0.0, 0.0, 1.0


@njit(cache=True)
def _frames(parents, placements, kinds, axes, index, q, work, scratch, world) -> None:  # type: ignore[no-untyped-def]
    """``work[j] = oMi[j]`` and ``world[j]`` its motion axis in the base frame, for every
    joint (``scratch``: (2, 4, 4))."""
    motion, placed = scratch[0], scratch[1]
    work[0] = 0.0
    for r in range(4):
        work[0, r, r] = 1.0
    for j in range(1, parents.shape[0]):
        _motion(kinds[j], axes[j], q[index[j]], motion)
        _compose(work[parents[j]], placements[j], placed)
        _compose(placed, motion, work[j])
        rot, u = work[j], axes[j]
        for r in range(3):
            world[j, r] = rot[r, 0] * u[0] + rot[r, 1] * u[1] + rot[r, 2] * u[2]


@njit(cache=True)
def _frame_jacobian(f, origin, joint_frames, world, kinds, index, support, jac) -> None:  # type: ignore[no-untyped-def]
    """``[J_v; J_ω]`` (6, n) of the point ``origin`` moved by the joints supporting frame f."""
    jac[:, :] = 0.0
    for j in range(1, kinds.shape[0]):
        if not support[f, j]:
            continue
        rot = joint_frames[j]
        w0, w1, w2 = world[j, 0], world[j, 1], world[j, 2]
        c = index[j]
        if kinds[j] == 1:
            jac[0, c], jac[1, c], jac[2, c] = w0, w1, w2
            continue
        d0, d1, d2 = origin[0] - rot[0, 3], origin[1] - rot[1, 3], origin[2] - rot[2, 3]
        jac[0, c] = w1 * d2 - w2 * d1
        jac[1, c] = w2 * d0 - w0 * d2
        jac[2, c] = w0 * d1 - w1 * d0
        jac[3, c], jac[4, c], jac[5, c] = w0, w1, w2


@njit(cache=True)
def kinematics(  # type: ignore[no-untyped-def]
    parents, placements, kinds, axes, index, frame_joint, frame_placement, support, work,
    world, radius, q, origins, frame_axes, frame_jacobians, guarded, guarded_jacobians, tool,
    tool_jac,
) -> int:  # fmt: skip
    """Frames, Jacobians and DV coordinates in place (see :class:`CompiledModel.kernel`)."""
    count = parents.shape[0]
    _frames(parents, placements, kinds, axes, index, q, work[:count], work[count:], world)
    m, n = frame_joint.shape[0], q.shape[0]
    pose = work[count]
    for f in range(m):
        _compose(work[frame_joint[f]], frame_placement[f], pose)
        origins[f] = pose[:3, 3]
        frame_axes[f] = pose[:3, 2]
        _frame_jacobian(f, origins[f], work, world, kinds, index, support, frame_jacobians[f])
    for f in range(m):
        x, y = origins[f, 0], origins[f, 1]
        rho2 = x * x + y * y
        rho = math.sqrt(rho2)
        if not rho >= RHO_MIN:
            return f
        guarded[f, 0] = radius * math.atan2(y, x)
        guarded[f, 1] = origins[f, 2]
        guarded[f, 2] = rho - radius
        jv = frame_jacobians[f]
        for c in range(n):
            jx, jy = jv[0, c], jv[1, c]
            guarded_jacobians[f, 0, c] = radius / rho2 * (x * jy - y * jx)
            guarded_jacobians[f, 1, c] = jv[2, c]
            guarded_jacobians[f, 2, c] = x / rho * jx + y / rho * jy
    tool[:3] = guarded[m - 1]
    tool_jac[:3] = guarded_jacobians[m - 1]
    tool[3] = _heading(origins[m - 1], frame_axes[m - 1], frame_jacobians[m - 1], tool_jac[3])
    return -1


@njit(cache=True)
def _heading(origin, axis, jac, row) -> float:  # type: ignore[no-untyped-def]
    """``α`` and ``∂α/∂Q`` (into ``row``): :func:`dvqp.kinematics.developed_view.heading_row`."""
    ox, oy = origin[0], origin[1]
    zx, zy, zz = axis[0], axis[1], axis[2]
    rho = math.hypot(ox, oy)
    c = (ox * zy - oy * zx) / rho
    s = zz
    k = 1.0 / max(c * c + s * s, HEADING_FLOOR)
    dc_ox = zy / rho - c * ox / (rho * rho)
    dc_oy = -zx / rho - c * oy / (rho * rho)
    dox, doy = -s * dc_ox * k, -s * dc_oy * k
    dzx, dzy, dzz = s * oy / rho * k, -s * ox / rho * k, c * k
    w3, w4, w5 = zy * dzz - zz * dzy, zz * dzx - zx * dzz, zx * dzy - zy * dzx
    for col in range(row.shape[0]):
        row[col] = dox * jac[0, col] + doy * jac[1, col] + w3 * jac[3, col]
        row[col] += w4 * jac[4, col] + w5 * jac[5, col]
    return math.atan2(s, c)
