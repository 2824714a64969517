"""A serial arm from a URDF file, with ``continuous`` joints as revolute ones without limits."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin

from dvqp._files import c_output_captured
from dvqp.errors import DvqpError, ParameterError


def urdf_model(path: str | Path) -> pin.Model:
    """The Pinocchio model of the URDF file ``path``, each continuous joint (nq = 2) a revolute
    one (nq = 1) without limits (errors: see :meth:`dvqp.Robot.from_urdf`)."""
    noise: list[str] = []
    try:
        with c_output_captured(noise):
            model = pin.buildModelFromUrdf(str(path))
    except (RuntimeError, ValueError) as exc:
        detail = f" ({noise[0]})" if noise else ""
        raise DvqpError(f"{path}: cannot load URDF: {exc}{detail}") from exc
    return _bounded_revolute(model)


UNBOUNDED_REVOLUTE = {"JointModelRUBX": pin.JointModelRX, "JointModelRUBY": pin.JointModelRY,
                      "JointModelRUBZ": pin.JointModelRZ}  # fmt: skip
"""Pinocchio's joints for a URDF ``continuous`` joint about x, y, z (nq = 2: cos, sin) and their
nq = 1 twins (any other axis: ``JointModelRevoluteUnboundedUnaligned``, see :func:`_twin`)."""


def _bounded_revolute(model: pin.Model) -> pin.Model:
    """``model`` with each continuous joint as a revolute one, joints, bodies and frames keeping
    their names, placements, inertias and order; any other joint with ``nq != nv`` is refused."""
    twins = [_twin(model.joints[i]) for i in range(1, model.njoints)]
    for name, joint, twin in zip(model.names[1:], model.joints[1:], twins, strict=True):
        if joint.nq != joint.nv and twin is None:
            raise ParameterError(
                "urdf", f"joint {name!r} is a {joint.shortname().removeprefix('JointModel')} "
                "joint: only revolute, continuous and prismatic joints are supported"
            )  # fmt: skip
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
        out.addJoint(model.parents[i], joint.extract() if twin is None else twin,
                     model.jointPlacements[i], model.names[i], model.effortLimit[v],
                     model.velocityLimit[v], lo, hi)  # fmt: skip
        out.appendBodyToJoint(i, model.inertias[i], pin.SE3.Identity())
    for frame in list(model.frames)[1:]:
        out.addFrame(pin.Frame(frame), False)
    return out


def _twin(joint: pin.JointModel) -> pin.JointModel | None:
    """The nq = 1 revolute joint of a continuous (nq = 2) one; None for any other joint."""
    kind = joint.shortname()
    if kind in UNBOUNDED_REVOLUTE:
        return UNBOUNDED_REVOLUTE[kind]()
    if kind != "JointModelRevoluteUnboundedUnaligned":
        return None
    data = joint.createData()  # the axis is not exposed: read it from the motion subspace
    joint.calc(data, np.array([1.0, 0.0]))
    return pin.JointModelRevoluteUnaligned(*np.asarray(data.S, dtype=float).reshape(6)[3:])
