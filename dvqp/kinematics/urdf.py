"""A serial arm from a URDF file, with ``continuous`` joints as revolute ones without limits and
``<mimic>`` joints as Pinocchio's mimic joints (no coordinate of their own)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin

from dvqp.errors import RobotFileError
from dvqp.kinematics.urdf_check import Mimic, read_urdf
from solvers.c_output import c_output_captured


def urdf_model(path: str | Path) -> pin.Model:
    """The Pinocchio model of the URDF file ``path``, checked first (:func:`read_urdf`), each
    continuous joint (nq = 2) a revolute one (nq = 1) without limits, each mimic joint
    Pinocchio's (its master's limits narrowed to keep it within its own: :func:`_narrowed`)
    (errors: see :meth:`dvqp.Robot.from_urdf`)."""
    checked = read_urdf(path)
    noise: list[str] = []
    try:
        with c_output_captured(noise):
            model = pin.buildModelFromXML(checked.text, mimic=bool(checked.mimics))
    except (RuntimeError, ValueError) as exc:
        detail = f" ({noise[0]})" if noise else ""
        raise RobotFileError(str(path), f"cannot load URDF: {exc}{detail}") from exc
    model = _bounded_revolute(model)
    for mimic in checked.mimics:
        _narrowed(model, mimic, str(path))
    if model.nq != checked.actuated:  # the checks and the parser must agree on the joints
        raise RobotFileError(
            str(path),
            f"the URDF parser read {model.nq} joint coordinates, "
            f"the file has {checked.actuated} joints that move",
        )
    return model


def _narrowed(model: pin.Model, mimic: Mimic, path: str) -> None:
    """Narrow the position and velocity limits of ``mimic``'s master in ``model`` so that the
    mimic joint, ``a q + b``, keeps within its own: ``q`` in ``[(lower − b)/a, (upper − b)/a]``
    (ordered by the sign of ``a``), ``|q̇| ≤ velocity/|a|``."""
    i = model.joints[model.getJointId(mimic.master)].idx_q
    a, b = mimic.multiplier, mimic.offset
    ends = sorted(((mimic.lower - b) / a, (mimic.upper - b) / a))
    lo = max(float(model.lowerPositionLimit[i]), ends[0])
    hi = min(float(model.upperPositionLimit[i]), ends[1])
    if lo > hi:
        raise RobotFileError(
            path,
            f"joint {mimic.joint!r} mimics {mimic.master!r}: no position of "
            f"{mimic.master!r} keeps both within their limits",
        )
    lower, upper = np.array(model.lowerPositionLimit), np.array(model.upperPositionLimit)
    lower[i], upper[i] = lo, hi
    model.lowerPositionLimit, model.upperPositionLimit = lower, upper
    if mimic.velocity > 0.0:
        speed, velocity = mimic.velocity / abs(a), np.array(model.velocityLimit)
        velocity[i] = speed if not velocity[i] > 0.0 else min(velocity[i], speed)
        model.velocityLimit = velocity


UNBOUNDED_REVOLUTE = {
    "JointModelRUBX": pin.JointModelRX,
    "JointModelRUBY": pin.JointModelRY,
    "JointModelRUBZ": pin.JointModelRZ,
}
"""Pinocchio's joints for a URDF ``continuous`` joint about x, y, z (nq = 2: cos, sin) and their
nq = 1 twins (any other axis: ``JointModelRevoluteUnboundedUnaligned``, see :func:`_twin`)."""


def _bounded_revolute(model: pin.Model) -> pin.Model:
    """``model`` with each continuous joint as a revolute one, joints, bodies and frames keeping
    their names, placements, inertias and order (:func:`read_urdf` let no other joint with
    ``nq != nv`` through)."""
    twins = [_twin(model.joints[i]) for i in range(1, model.njoints)]
    if all(twin is None for twin in twins):
        return model
    out = pin.Model()
    out.name = model.name
    for i, twin in enumerate(twins, start=1):
        joint = model.joints[i]
        q = slice(joint.idx_q, joint.idx_q + joint.nq)
        lo, hi = model.lowerPositionLimit[q], model.upperPositionLimit[q]
        if twin is not None:
            lo, hi = np.array([-np.inf]), np.array([np.inf])
        v = slice(joint.idx_v, joint.idx_v + joint.nv)
        out.addJoint(
            model.parents[i],
            joint.extract() if twin is None else twin,
            model.jointPlacements[i],
            model.names[i],
            model.effortLimit[v],
            model.velocityLimit[v],
            lo,
            hi,
        )
        out.appendBodyToJoint(i, model.inertias[i], pin.SE3.Identity())
    for frame in list(model.frames)[1:]:
        out.addFrame(pin.Frame(frame), False)
    return out


def _twin(joint: pin.JointModel) -> pin.JointModel | None:
    """The nq = 1 revolute joint of a continuous (nq = 2) one; None for any other joint."""
    joint_type = joint.shortname()
    if joint_type in UNBOUNDED_REVOLUTE:
        return UNBOUNDED_REVOLUTE[joint_type]()
    if joint_type != "JointModelRevoluteUnboundedUnaligned":
        return None
    data = joint.createData()  # the axis is not exposed: read it from the motion subspace
    joint.calc(data, np.array([1.0, 0.0]))
    return pin.JointModelRevoluteUnaligned(*np.asarray(data.S, dtype=float).reshape(6)[3:])
