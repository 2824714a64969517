"""Compiled kinematics of a Pinocchio model: frames, frame Jacobians and the developed view.

:class:`ModelArrays` reads a Pinocchio model once (joint placements, axes, parents, the
guarded frames' placements); :func:`kinematics` evaluates it in one compiled call:
``oMi = oMi[parent] · jointPlacement · M_j(s_j q_i + o_j)`` for revolute and prismatic joints
(``q_i`` the joint's own coordinate, ``s_j = 1``, ``o_j = 0``; a mimic joint follows its
master's coordinate ``q_i`` with Pinocchio's ``scaling`` and ``offset``), the frames
``oMf = oMi[parentJoint] · placement``, their LOCAL_WORLD_ALIGNED Jacobians (``s_j ω × (p − o_j)``
per supporting revolute joint, added into column ``i``) and the developed-view map of
:mod:`dvqp.kinematics.developed_view`, written in place into
:class:`~dvqp.workspace.StateBuffers`. This is dvqp's only implementation of its kinematics;
the tests hold it to Pinocchio's own to 1e-12.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from dvqp.errors import ParameterError
from dvqp.kinematics.developed_view import HEADING_FLOOR, RHO_MIN
from solvers.jit import njit

Array = NDArray[np.float64]

REVOLUTE, PRISMATIC = 0, 1
_ALIGNED = {
    f"JointModel{kind}{axis}": (code, tuple(float(a == axis) for a in "XYZ"))
    for kind, code in (("R", REVOLUTE), ("P", PRISMATIC))
    for axis in "XYZ"
}
_UNALIGNED = {"JointModelRevoluteUnaligned": REVOLUTE, "JointModelPrismaticUnaligned": PRISMATIC}


@dataclass(frozen=True)
class ModelArrays:
    """A Pinocchio model's constants as :func:`kinematics` reads them (J joints, joint 0 the
    universe; m guarded frames: the body points, the tool (frame ``tool``), the rail point).

    Attributes
    ----------
    parents, kinds, index : (J,) int64
        Parent joint; 0 revolute, 1 prismatic; ``idx_q`` (a mimic joint's: its master's).
    scale, offset : (J,)
        The joint's coordinate is ``scale · q[index] + offset`` (1 and 0 but for a mimic
        joint: Pinocchio's ``scaling`` and ``offset``).
    placements : (J, 4, 4)
        ``jointPlacements``.
    axes : (J, 3)
        Unit motion axis of each joint in its own frame.
    frame_joint : (m,) int64
        Parent joint of each guarded frame.
    frame_placement : (m, 4, 4)
        The frames' placements in their joints.
    support : (m, J) bool
        Whether joint j moves frame f.
    work, world : (J + 2, 4, 4), (J, 3)
        Scratch: the joints' placements in the base frame, then two transforms; their axes.
    tool : int
        Index of the tool among the guarded frames (k, the number of body points).
    """

    parents: NDArray[np.int64]
    kinds: NDArray[np.int64]
    index: NDArray[np.int64]
    scale: Array
    offset: Array
    placements: Array
    axes: Array
    frame_joint: NDArray[np.int64]
    frame_placement: Array
    support: NDArray[np.bool_]
    work: Array
    world: Array
    tool: int

    @classmethod
    def of(cls, model: pin.Model, frame_ids: Sequence[int], tool: int) -> ModelArrays:
        """The constants of ``model`` for the guarded frames ``frame_ids``, ``tool`` the index
        of the tool frame among them.

        Raises
        ------
        ParameterError
            ``model``: a joint is neither revolute nor prismatic about a fixed axis.
        """
        count = model.njoints
        kinds, axes = np.zeros(count, np.int64), np.zeros((count, 3))
        scale, offset = np.ones(count), np.zeros(count)
        for j in range(1, count):
            kinds[j], axes[j], scale[j], offset[j] = _motion_of(model.joints[j], model.names[j])
        frames = [model.frames[i] for i in frame_ids]
        support = np.zeros((len(frames), count), dtype=np.bool_)
        for f, frame in enumerate(frames):
            j = frame.parentJoint
            while j > 0:
                support[f, j] = True
                j = model.parents[j]
        return cls(
            parents=np.array(model.parents, dtype=np.int64),
            kinds=kinds,
            index=np.array([max(model.joints[j].idx_q, 0) for j in range(count)], np.int64),
            scale=scale,
            offset=offset,
            placements=np.array([p.homogeneous for p in model.jointPlacements]),
            axes=axes,
            frame_joint=np.array([f.parentJoint for f in frames], dtype=np.int64),
            frame_placement=np.array([f.placement.homogeneous for f in frames]),
            support=support,
            work=np.zeros((count + 2, 4, 4)),
            world=np.zeros((count, 3)),
            tool=int(tool),
        )


def _motion_of(joint: pin.JointModel, name: str) -> tuple[int, Array, float, float]:
    """``(kind, unit axis, scale, offset)`` of a revolute or prismatic joint, or of a mimic
    joint of one (its motion subspace is ``scaling`` times its own joint's: axis and kind read
    there); ParameterError otherwise."""
    short = joint.shortname()
    if short in _ALIGNED:
        code, axis = _ALIGNED[short]
        return code, np.array(axis), 1.0, 0.0
    if short in _UNALIGNED:
        axis = np.array(joint.extract().axis, dtype=np.float64)
        return _UNALIGNED[short], axis / np.linalg.norm(axis), 1.0, 0.0
    if short == "JointModelMimic":
        return _mimic(joint, name)
    kind = short.removeprefix("JointModel")
    raise ParameterError(
        "model",
        f"joint {name!r} is a {kind} joint: only revolute and "
        "prismatic joints about a fixed axis are supported",
    )


def _mimic(joint: pin.JointModel, name: str) -> tuple[int, Array, float, float]:
    """``(kind, unit axis, scaling, offset)`` of a mimic joint of a revolute or prismatic one
    (``S = scaling · [v; ω]`` of its own joint's axis); ParameterError otherwise."""
    mimic = joint.extract()
    scaling, offset = float(mimic.scaling), float(mimic.offset)
    data = joint.createData()
    joint.calc(data, np.zeros(joint.idx_q + 1))
    motion = np.asarray(data.S, dtype=np.float64).reshape(6)
    linear, angular = motion[:3], motion[3:]
    if scaling == 0.0 or not math.isfinite(scaling) or not math.isfinite(offset):
        raise ParameterError("model", f"mimic joint {name!r}: its multiplier must be finite, not 0")
    kind = REVOLUTE if np.any(angular) else PRISMATIC
    axis = (angular if kind == REVOLUTE else linear) / scaling
    if np.any(linear) == np.any(angular) or not math.isclose(np.linalg.norm(axis), 1.0):
        raise ParameterError(
            "model", f"mimic joint {name!r}: only a revolute or prismatic joint can mimic"
        )
    return kind, axis / np.linalg.norm(axis), scaling, offset


@njit(inline="always")
def _motion(kind: int, axis: Array, value: float, out: Array) -> None:
    """``M_j(q_j)``: rotation by ``value`` about ``axis`` (Rodrigues) or translation along it."""
    for r in range(4):
        for c in range(4):
            out[r, c] = 1.0 if r == c else 0.0
    if kind == PRISMATIC:
        for r in range(3):
            out[r, 3] = axis[r] * value
        return
    c, s = math.cos(value), math.sin(value)
    x, y, z = axis[0], axis[1], axis[2]
    v = 1.0 - c
    out[0, 0], out[0, 1], out[0, 2] = c + x * x * v, x * y * v - z * s, x * z * v + y * s
    out[1, 0], out[1, 1], out[1, 2] = y * x * v + z * s, c + y * y * v, y * z * v - x * s
    out[2, 0], out[2, 1], out[2, 2] = z * x * v - y * s, z * y * v + x * s, c + z * z * v


@njit(inline="always")
def _compose(a: Array, b: Array, out: Array) -> None:
    """``out = a · b`` of two rigid transforms (4, 4)."""
    for r in range(3):
        a0, a1, a2 = a[r, 0], a[r, 1], a[r, 2]
        for c in range(4):
            out[r, c] = a0 * b[0, c] + a1 * b[1, c] + a2 * b[2, c]
        out[r, 3] += a[r, 3]
    out[3, 0], out[3, 1], out[3, 2], out[3, 3] = 0.0, 0.0, 0.0, 1.0


@njit(inline="always")
def _joints(model, q) -> None:  # type: ignore[no-untyped-def]
    """``model.work[j] = oMi[j]`` and ``model.world[j]`` its motion axis in the base frame."""
    work, count = model.work, model.parents.shape[0]
    motion, placed = work[count], work[count + 1]
    for r in range(4):
        for c in range(4):
            work[0, r, c] = 1.0 if r == c else 0.0
    for j in range(1, count):
        value = model.scale[j] * q[model.index[j]] + model.offset[j]
        _motion(model.kinds[j], model.axes[j], value, motion)
        _compose(work[model.parents[j]], model.placements[j], placed)
        _compose(placed, motion, work[j])
        u = model.axes[j]
        for r in range(3):
            model.world[j, r] = work[j, r, 0] * u[0] + work[j, r, 1] * u[1] + work[j, r, 2] * u[2]


@njit(inline="always")
def _frame_jacobian(model, f, origin, jac) -> None:  # type: ignore[no-untyped-def]
    """``[J_v; J_ω]`` (6, n) of the point ``origin`` moved by the joints supporting frame f
    (a mimic joint's motion, ``scale`` times its own, added into its master's column)."""
    for r in range(6):
        for c in range(jac.shape[1]):
            jac[r, c] = 0.0
    for j in range(1, model.kinds.shape[0]):
        if not model.support[f, j]:
            continue
        s = model.scale[j]
        w0, w1, w2 = s * model.world[j, 0], s * model.world[j, 1], s * model.world[j, 2]
        c = model.index[j]
        if model.kinds[j] == PRISMATIC:
            jac[0, c] += w0
            jac[1, c] += w1
            jac[2, c] += w2
            continue
        o = model.work[j]
        d0, d1, d2 = origin[0] - o[0, 3], origin[1] - o[1, 3], origin[2] - o[2, 3]
        jac[0, c] += w1 * d2 - w2 * d1
        jac[1, c] += w2 * d0 - w0 * d2
        jac[2, c] += w0 * d1 - w1 * d0
        jac[3, c] += w0
        jac[4, c] += w1
        jac[5, c] += w2


@njit(separate=True)
def kinematics(model, radius, state) -> int:  # type: ignore[no-untyped-def]
    """Frames, frame Jacobians and DV coordinates of ``state.q``, written into ``state``
    (a packed :class:`~dvqp.workspace.StateBuffers`; ``model`` a packed :class:`ModelArrays`,
    ``radius`` the pipe's, m).

    Returns −1, or the index of a guarded frame on the pipe axis (a singular configuration:
    its DV coordinates are undefined). Raises ValueError if ``state`` is not sized for the
    model's guarded frames.
    """
    count, m = model.parents.shape[0], model.frame_joint.shape[0]
    if state.guarded.shape[0] != m or state.origins.shape[0] != m:
        raise ValueError("kinematics: the state's buffers are not sized for this model")
    _joints(model, state.q)
    pose = model.work[count]
    for f in range(m):
        _compose(model.work[model.frame_joint[f]], model.frame_placement[f], pose)
        for r in range(3):
            state.origins[f, r], state.axes[f, r] = pose[r, 3], pose[r, 2]
        _frame_jacobian(model, f, state.origins[f], state.frame_jacobians[f])
        if not _developed(
            radius,
            state.origins[f],
            state.frame_jacobians[f],
            state.guarded[f],
            state.guarded_jacobians[f],
        ):
            return f
    t = model.tool
    for c in range(state.q.shape[0]):
        for r in range(3):
            state.tool_jacobian[r, c] = state.guarded_jacobians[t, r, c]
    for r in range(3):
        state.tool[r] = state.guarded[t, r]
    state.tool[3] = _heading(
        state.origins[t], state.axes[t], state.frame_jacobians[t], state.tool_jacobian[3]
    )
    return -1


@njit(inline="always")
def _developed(radius, origin, jac, out, rows) -> bool:  # type: ignore[no-untyped-def]
    """``[l, z, h]`` of a point (``l = R atan2(y, x)``, ``z``, ``h = ρ − R``) and its rows
    ``∂[l, z, h]/∂Q`` through the point's linear Jacobian; False on the pipe axis."""
    x, y = origin[0], origin[1]
    rho2 = x * x + y * y
    rho = math.sqrt(rho2)
    if not rho >= RHO_MIN:
        return False
    out[0], out[1], out[2] = radius * math.atan2(y, x), origin[2], rho - radius
    for c in range(jac.shape[1]):
        jx, jy = jac[0, c], jac[1, c]
        rows[0, c] = radius / rho2 * (x * jy - y * jx)
        rows[1, c] = jac[2, c]
        rows[2, c] = x / rho * jx + y / rho * jy
    return True


@njit(inline="always")
def _heading(origin, axis, jac, row) -> float:  # type: ignore[no-untyped-def]
    """The heading ``α = atan2(z_z, (O_x z_y − O_y z_x)/ρ)`` (rad) of the tool axis on the
    surface, and ``∂α/∂Q`` into ``row``: with ``ż = ω × z``,
    ``∂α/∂Q = ∂α/∂O·J_v + (z × ∂α/∂z)·J_ω``. ``c² + s²`` is floored at
    :data:`~dvqp.kinematics.developed_view.HEADING_FLOOR` (the axis radial)."""
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
