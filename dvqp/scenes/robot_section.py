"""Reader of a scene file's ``[robot]`` table: the arm, where its base is, its limits, q0 and
the weights."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike, NDArray

from dvqp import _validate
from dvqp.errors import DvqpError, ParameterError
from dvqp.kinematics.robot import Robot
from dvqp.kinematics.urdf_check import read_urdf
from dvqp.scenes.fields import Bound, Fields, join

LINK_LENGTH = Bound(0.0, 10.0, "m")
ANGLE = Bound(-1000.0, 1000.0, "rad")
"""A joint angle or a finite joint limit (``±inf``: no limit)."""
JOINT_SPEED = Bound(0.0, 1000.0, "rad/s", strict=True)
JOINT_WEIGHT = Bound(1e-6, 1e6)
BASE_OFFSET = Bound(-100.0, 100.0, "m")
"""A coordinate of the base frame's origin in the pipe's frame."""
BASE_ANGLE = Bound(-10.0, 10.0, "rad")
"""A roll, pitch or yaw angle of the base frame."""
BASE_KEYS = ("xyz", "rpy")
ROBOT_KEYS = (
    "model",
    "link_lengths",
    "urdf",
    "points",
    "tool",
    "rail",
    "base",
    "q0",
    "q_min",
    "q_max",
    "qd_max",
    "qdd_max",
    "weights",
)
MODELS = ("ndt13",)


def robot(
    f: Fields, doc: dict[str, Any], base_dir: Path
) -> tuple[Robot, NDArray[np.float64], NDArray[np.float64]]:
    """The arm (its base placed by ``[robot.base]``), its start configuration (rad) and the
    diagonal of W, each checked.

    Every per-joint array is checked against the arm's joint count (13, or the URDF file's
    joints that move, mimic joints not counted, the file checked) before the arm is built.
    """
    t = f.table(doc, "robot", "", ROBOT_KEYS)
    base = _base(f, t)
    n = _joint_count(f, t, base_dir)
    q0 = f.vector(t, "q0", "robot", n, within=ANGLE)
    weights = f.vector(t, "weights", "robot", n, scalar=True, default=1.0, within=JOINT_WEIGHT)
    limits = _limits(f, t, n)
    f.vector(t, "qdd_max", "robot", n, scalar=True, default=1.0, infinite=True)  # bounds: limits
    arm = _arm(f, t, base_dir, limits)
    if base is not None:
        arm = arm.placed(base)
    for i, (q, lo, hi) in enumerate(zip(q0, arm.q_min, arm.q_max, strict=True)):
        if not lo - 1e-12 <= q <= hi + 1e-12:
            f.fail(f"robot.q0[{i}]", f"{q:g} rad is outside [q_min, q_max] = [{lo:g}, {hi:g}] rad")
    return arm, _validate.readonly(q0), _validate.readonly(weights)


def _base(f: Fields, t: dict[str, Any]) -> NDArray[np.float64] | None:
    """``[robot.base]``: the arm's base frame in the pipe's frame, (4, 4), from ``xyz`` (m) and
    ``rpy`` (rad: roll about x, pitch about y, yaw about z, fixed axes, as a URDF origin); None
    if absent."""
    if "base" not in t:
        return None
    b = f.table(t, "base", "robot", BASE_KEYS)
    xyz = f.vector(b, "xyz", "robot.base", 3, default=[0.0, 0.0, 0.0], within=BASE_OFFSET)
    rpy = f.vector(b, "rpy", "robot.base", 3, default=[0.0, 0.0, 0.0], within=BASE_ANGLE)
    return base_transform(xyz, rpy)


def base_transform(xyz: ArrayLike, rpy: ArrayLike) -> NDArray[np.float64]:
    """The transform (4, 4) of a frame at ``xyz`` (m), turned by ``rpy`` (rad), as a URDF
    ``<origin>``: ``R = Rz(yaw) Ry(pitch) Rx(roll)``."""
    out = np.eye(4)
    out[:3, :3] = pin.rpy.rpyToMatrix(*np.asarray(rpy, dtype=np.float64))
    out[:3, 3] = np.asarray(xyz, dtype=np.float64)
    return out


def _joint_count(f: Fields, t: dict[str, Any], base_dir: Path) -> int:
    """13 for the built-in arm; for a URDF file, checked (:func:`read_urdf`), its number of
    revolute, continuous and prismatic joints. No model is built."""
    if ("model" in t) == ("urdf" in t):
        f.fail("robot", "give exactly one of 'model' (built in) or 'urdf' (a file)")
    if "model" in t:
        model = f.string(t, "model", "robot")
        if model not in MODELS:
            f.fail("robot.model", f"unknown model {model!r} (known: {', '.join(MODELS)})")
        return 13
    urdf = base_dir / f.string(t, "urdf", "robot")
    if not urdf.is_file():
        f.fail("robot.urdf", f"no such file: {urdf}")
    try:
        return read_urdf(urdf).actuated
    except DvqpError as exc:
        f.fail("robot.urdf", str(exc))


def _arm(f: Fields, t: dict[str, Any], base_dir: Path, limits: dict[str, Any]) -> Robot:
    """The arm (``model`` or ``urdf``, as :func:`_joint_count` checked) with the scene's
    ``limits`` (None: the arm's own)."""
    given = {k: v for k, v in limits.items() if v is not None}
    if "model" in t:
        for key in ("points", "tool", "rail"):
            if key in t:
                f.fail(join("robot", key), "only with 'urdf'")
        lengths = f.vector(t, "link_lengths", "robot", 7, within=LINK_LENGTH)
        with f.mapped("robot"):
            return Robot.ndt13(lengths, **given)
    if "link_lengths" in t:
        f.fail("robot.link_lengths", "only with model = 'ndt13'")
    urdf = base_dir / f.string(t, "urdf", "robot")
    points, tool = f.strings(t, "points", "robot"), f.string(t, "tool", "robot")
    rail = f.string(t, "rail", "robot") if "rail" in t else None
    try:
        loaded = Robot.from_urdf(urdf, points, tool, rail=rail)
    except ParameterError as exc:
        _frame_error(f, exc, tool, rail)
    except DvqpError as exc:
        f.fail("robot.urdf", str(exc))
    except (ArithmeticError, ValueError, RuntimeError) as exc:  # Pinocchio on a strange model
        f.fail("robot.urdf", f"{urdf}: cannot use this model ({exc})")
    with f.mapped("robot"):
        return Robot(
            loaded.model,
            points,
            tool,
            rail_frame=rail,
            base_frame=loaded.root_frame,
            name=loaded.name,
            names="frames",
            **{"qd_max": loaded.qd_max, **given},
        )


def _limits(f: Fields, t: dict[str, Any], n: int) -> dict[str, NDArray[np.float64] | None]:
    """q_min, q_max (±inf allowed: no limit) and qd_max as given, or None."""
    bounds = {"q_min": ANGLE, "q_max": ANGLE, "qd_max": JOINT_SPEED}
    return {
        key: f.vector(t, key, "robot", n, scalar=True, infinite=key != "qd_max", within=bound)
        if key in t
        else None
        for key, bound in bounds.items()
    }


def _frame_error(f: Fields, exc: ParameterError, tool: str, rail: str | None) -> None:
    """A URDF robot's complaint, named by the scene key it is about (model: ``robot.urdf``)."""
    if exc.name in ("model", "urdf"):
        f.fail("robot.urdf", exc.reason)
    if exc.name != "frames":
        f.fail(join("robot", exc.name), exc.reason)
    named = {f"no frame named {name!r}": key for key, name in (("tool", tool), ("rail", rail))}
    key = next((k for start, k in named.items() if exc.reason.startswith(start)), "points")
    f.fail(join("robot", key), exc.reason)
