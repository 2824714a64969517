"""Independent references for the kinematics tests.

dvqp computes its kinematics once, compiled (:func:`dvqp.kinematics.model.kinematics`). The
tests hold it to

* Pinocchio's own forward kinematics and LOCAL_WORLD_ALIGNED frame Jacobians
  (:func:`pinocchio_frames`), and
* the developed-view map written out in NumPy (:func:`dv_position`, :func:`dv_rows`,
  :func:`heading`, :func:`heading_row`: the package's NumPy code before the redesign), which
  :func:`reference` chains into every field of a :class:`~dvqp.KinematicState`;

and to finite differences (:func:`free_frame_robot` moves one frame anywhere, with any axis,
so that the map is checked frame by frame).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike, NDArray

from dvqp import Robot
from dvqp.errors import SingularConfigurationError
from dvqp.kinematics.dh import DHRow, fixed_part

Array = NDArray[np.float64]

LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
RHO_MIN = 1e-9
HEADING_FLOOR = 1e-6
FIELDS = (
    "q",
    "origins",
    "axes",
    "frame_jacobians",
    "guarded",
    "guarded_jacobians",
    "points",
    "point_jacobians",
    "tool",
    "tool_jacobian",
)
"""The array fields of a :class:`~dvqp.KinematicState`."""


def pinocchio_frames(robot: Robot, q: ArrayLike) -> tuple[Array, Array, Array]:
    """Origins (k+1, 3), unit z axes (k+1, 3) and ``[J_v; J_ω]`` (k+1, 6, n) of the
    robot's guarded frames, by Pinocchio (its own data, LOCAL_WORLD_ALIGNED)."""
    model = robot.model
    data = model.createData()
    qv = np.asarray(q, dtype=np.float64)
    pin.computeJointJacobians(model, data, qv)
    pin.updateFramePlacements(model, data)
    frames = np.array([data.oMf[i].homogeneous for i in robot.frame_ids])
    jac = np.array([pin.getFrameJacobian(model, data, i, LWA) for i in robot.frame_ids])
    return frames[:, :3, 3].copy(), frames[:, :3, 2].copy(), jac


def dv_position(origins: ArrayLike, radius: float) -> Array:
    """``[l, z, h]`` (m) of k points ``origins`` (k, 3): ``l = R atan2(y, x)``, ``h = ρ − R``."""
    o = np.asarray(origins, dtype=np.float64)
    rho = np.hypot(o[:, 0], o[:, 1])
    if not (rho >= RHO_MIN).all():
        raise SingularConfigurationError(f"point lies on the pipe axis (rho = {rho.min():.3g} m)")
    return np.column_stack([radius * np.arctan2(o[:, 1], o[:, 0]), o[:, 2], rho - radius])


def dv_rows(origins: ArrayLike, linear_jacobians: ArrayLike, radius: float) -> Array:
    """``∂[l, z, h]/∂O · ∂O/∂Q`` (k, 3, n) of k points with linear Jacobians (k, 3, n)."""
    o = np.asarray(origins, dtype=np.float64)
    jv = np.asarray(linear_jacobians, dtype=np.float64)
    x, y = o[:, 0, None], o[:, 1, None]
    rho2 = x * x + y * y
    rho = np.sqrt(rho2)
    jx, jy = jv[:, 0], jv[:, 1]
    return np.stack(
        [radius / rho2 * (x * jy - y * jx), jv[:, 2], x / rho * jx + y / rho * jy], axis=1
    )


def heading(origin: ArrayLike, axis: ArrayLike) -> tuple[float, Array]:
    """Heading ``α = atan2(z_z, (O_x z_y − O_y z_x)/ρ)`` (rad) of the unit ``axis`` at
    ``origin`` and ``∂α/∂[O; z]`` (6,), ``c² + s²`` floored at :data:`HEADING_FLOOR`."""
    ox, oy, _ = np.asarray(origin, dtype=np.float64)
    zx, zy, zz = np.asarray(axis, dtype=np.float64)
    rho = math.hypot(ox, oy)
    if rho < RHO_MIN:
        raise SingularConfigurationError(f"frame lies on the pipe axis (rho = {rho:.3g} m)")
    c = (ox * zy - oy * zx) / rho
    s = zz
    k = 1.0 / max(c * c + s * s, HEADING_FLOOR)
    dc_ox = zy / rho - c * ox / (rho * rho)
    dc_oy = -zx / rho - c * oy / (rho * rho)
    grad = np.array(
        [-s * dc_ox * k, -s * dc_oy * k, 0.0, s * oy / rho * k, -s * ox / rho * k, c * k]
    )
    return math.atan2(s, c), grad


def heading_row(origin: ArrayLike, axis: ArrayLike, frame_jacobian: ArrayLike) -> Array:
    """``∂α/∂Q`` (n,): ``∂α/∂O·J_v + ∂α/∂z·ż`` with ``ż = ω × z = −S(z)·J_ω Q̇``."""
    jac = np.asarray(frame_jacobian, dtype=np.float64)
    grad = heading(origin, axis)[1]
    return grad[:3] @ jac[:3] - grad[3:] @ skew(axis) @ jac[3:]


def reference(robot: Robot, q: ArrayLike, radius: float) -> dict[str, Array]:
    """Every array field of ``KinematicState.compute(robot, q, radius)``, from Pinocchio and
    the NumPy developed-view map."""
    origins, axes, jac = pinocchio_frames(robot, q)
    guarded = dv_position(origins, radius)
    rows = dv_rows(origins, jac[:, :3], radius)
    t = robot.n_points  # the tool's frame: after the body points (the rail point, if any, last)
    alpha, _ = heading(origins[t], axes[t])
    return {
        "q": np.asarray(q, dtype=np.float64),
        "origins": origins,
        "axes": axes,
        "frame_jacobians": jac,
        "guarded": guarded,
        "guarded_jacobians": rows,
        "points": guarded[:t],
        "point_jacobians": rows[:t],
        "tool": np.append(guarded[t], alpha),
        "tool_jacobian": np.vstack([rows[t], heading_row(origins[t], axes[t], jac[t])]),
    }


def skew(v: ArrayLike) -> Array:
    """Skew-symmetric matrix ``S(v)`` with ``S(v)·u = v × u``, shape (3, 3)."""
    x, y, z = np.asarray(v, dtype=np.float64)
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def free_frame_robot() -> Robot:
    """A robot whose tool frame goes anywhere with any axis: joints ``PX, PY, PZ`` put its
    origin at ``q[:3]``, then ``RZ(q[3])·RY(q[4])`` turn its z axis to
    ``(cos q3 sin q4, sin q3 sin q4, cos q4)``. Body point ``"fixed"`` stays at
    ``(0.3, 0, 0)``; body point ``"riding"`` rides on the PY joint at ``(0.2, 0, 0.05)``."""
    model = pin.Model()
    parent = 0
    joints = (
        pin.JointModelPX(),
        pin.JointModelPY(),
        pin.JointModelPZ(),
        pin.JointModelRZ(),
        pin.JointModelRY(),
    )
    for i, joint in enumerate(joints):
        parent = model.addJoint(parent, joint, pin.SE3.Identity(), f"j{i}")
        if i == 1:
            riding = pin.SE3(np.eye(3), np.array([0.2, 0.0, 0.05]))
            model.addFrame(pin.Frame("riding", parent, 0, riding, pin.FrameType.OP_FRAME))
    fixed = pin.SE3(np.eye(3), np.array([0.3, 0.0, 0.0]))
    model.addFrame(pin.Frame("fixed", 0, 0, fixed, pin.FrameType.OP_FRAME))
    model.addFrame(pin.Frame("tool", parent, 0, pin.SE3.Identity(), pin.FrameType.OP_FRAME))
    return Robot(model, ["fixed", "riding"], "tool", q_min=-10.0, q_max=10.0, name="free-frame")


def free_frame_q(origin: ArrayLike, axis: ArrayLike) -> Array:
    """The configuration of :func:`free_frame_robot` with its tool at ``origin`` (m) and its
    z axis along ``axis`` (normalised)."""
    a = np.asarray(axis, dtype=np.float64)
    a = a / np.linalg.norm(a)
    return np.array(
        [
            *np.asarray(origin, dtype=np.float64),
            math.atan2(a[1], a[0]),
            math.acos(np.clip(a[2], -1.0, 1.0)),
        ]
    )


def on_surface(l: float, z: float, h: float, radius: float) -> Array:
    """The Cartesian point (m) at DV position ``(l, z, h)`` around a pipe of ``radius``."""
    phi = l / radius
    return np.array([(radius + h) * math.cos(phi), (radius + h) * math.sin(phi), z])


def dh_transform(row: DHRow, theta: float) -> NDArray[np.float64]:
    """Homogeneous transform ``T_i^{i-1}`` of one DH row at joint angle ``theta``, (4, 4)."""
    th = theta + row.theta_offset
    ct, st = np.cos(th), np.sin(th)
    rz = np.array([[ct, -st, 0.0, 0.0], [st, ct, 0.0, 0.0], [0, 0, 1.0, 0], [0, 0, 0, 1.0]])
    return rz @ fixed_part(row)


def forward_dh(
    table: Sequence[DHRow], q: ArrayLike, tool: NDArray[np.float64] | None = None
) -> list[NDArray[np.float64]]:
    """Plain DH product: the transforms ``T_1^0, …, T_n^0`` and, if given, ``T_e^0``.

    Parameters
    ----------
    table
        The n DH rows.
    q
        Joint angles, rad, shape (n,).
    tool
        ``T_e^n``, shape (4, 4), or None.

    Returns
    -------
    list of ndarray
        n transforms (n+1 with a tool), each (4, 4), in the base frame.
    """
    qv = np.asarray(q, dtype=float)
    out = []
    t = np.eye(4)
    for row, th in zip(table, qv, strict=True):
        t = t @ dh_transform(row, th)
        out.append(t)
    if tool is not None:
        out.append(t @ tool)
    return out
