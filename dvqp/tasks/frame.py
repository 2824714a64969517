"""Hold a named Pinocchio frame at a pose: its position and/or orientation (pink's FrameTask)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike, NDArray

from dvqp import _validate
from dvqp.errors import ParameterError
from dvqp.kinematics.robot import Robot
from dvqp.kinematics.state import KinematicState
from dvqp.tasks.task import (
    DEFAULT_GAIN,
    Deviation,
    Samples,
    Task,
    TaskRows,
    check_components,
    check_priority,
    check_weight,
)

COMPONENTS = ("position", "orientation")
"""What of the frame's pose the task holds: its origin (3 rows, m) and its rotation (3, rad)."""


class FrameTask(Task):
    """``[J_v; J_ω]_c Q̇ = K [p* − p; log(R* Rᵀ)]_c``: a frame of the arm's model moves toward a
    target pose, in position and/or orientation.

    ``p``, ``R`` are the frame's origin and rotation in the base frame (the pipe's: its z axis
    the pipe axis) and ``[J_v; J_ω]`` its Jacobian in the base orientation (Pinocchio's
    LOCAL_WORLD_ALIGNED: ``ṗ = J_v Q̇``, ``ω = J_ω Q̇``); ``log(R* Rᵀ)`` is the rotation vector
    (base frame, rad) that turns ``R`` into ``R*``, so ``d/dt log(R* Rᵀ) = −ω`` where they
    meet. For a URDF arm whose frames are named in its file; the rows are computed in NumPy with
    Pinocchio, through the run's hooks.

    Parameters
    ----------
    robot
        The arm whose model holds the frame.
    frame
        The frame's name in the model.
    components
        A non-empty subset of ``("position", "orientation")``.
    position, rotation
        The target origin (m, shape (3,)) and rotation (a rotation matrix (3, 3)). None: the
        frame's where the run starts (the first state the task is computed at).
    gain
        ``K``, 1/s, >= 0.
    priority, weight
        As every task's (:class:`~dvqp.tasks.Task`).

    Raises
    ------
    ParameterError
        An unknown frame (the message lists the model's frames), an empty, unknown or repeated
        component, a target that is not a position or a rotation, a gain < 0, a priority not an
        integer >= 1, a weight not > 0.
    """

    name = "frame"
    hard = True

    def __init__(
        self,
        robot: Robot,
        frame: str,
        components: Sequence[str] = COMPONENTS,
        *,
        position: ArrayLike | None = None,
        rotation: ArrayLike | None = None,
        gain: float = DEFAULT_GAIN,
        priority: int = 1,
        weight: float = 1.0,
    ) -> None:
        model = robot.model
        if not isinstance(frame, str) or not model.existFrame(frame):
            known = ", ".join(f.name for f in model.frames)
            raise ParameterError("frame", f"no frame named {frame!r} (model has: {known})")
        self.robot, self.frame = robot, frame
        self.frame_id = int(model.getFrameId(frame))
        self.components = check_components("components", components, COMPONENTS)
        self.position = None if position is None else _validate.vector("position", position, 3)
        self.rotation = None if rotation is None else _rotation(rotation)
        self.gain = _validate.positive("gain", gain, strict=False)
        self.priority = check_priority(priority)
        self.weight = check_weight(weight)
        self._data = model.createData()

    def __repr__(self) -> str:
        return f"FrameTask({self.frame!r}, {self.components!r}, priority={self.priority})"

    @property
    def label(self) -> str:
        """``"frame probe position"``."""
        return f"frame {self.frame} {', '.join(self.components)}"

    def pose(self, q: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The frame's origin (3,) (m) and rotation (3, 3) at ``q`` (rad, shape (n,))."""
        model, data = self.robot.model, self._data
        pin.framesForwardKinematics(model, data, np.asarray(q, dtype=np.float64))
        placement = data.oMf[self.frame_id]
        return np.array(placement.translation), np.array(placement.rotation)

    def errors(
        self, origin: NDArray[np.float64], rotation: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """``[p* − p; log(R* Rᵀ)]`` of the chosen components (3 or 6,), m and rad; a target
        not given is taken where the frame is now, and kept from then on."""
        if self.position is None:
            self.position = origin.copy()
        if self.rotation is None:
            self.rotation = rotation.copy()
        parts = {
            "position": self.position - origin,
            "orientation": np.array(pin.log3(self.rotation @ rotation.T)),
        }
        return np.concatenate([parts[c] for c in self.components])

    def compute(self, state: KinematicState, command: NDArray[np.float64], dt: float) -> TaskRows:
        """The Jacobian's chosen rows (3 or 6, n) and ``K`` times :meth:`errors` at ``state``."""
        model, data = self.robot.model, self._data
        q = np.asarray(state.q, dtype=np.float64)
        jacobian = pin.computeFrameJacobian(
            model, data, q, self.frame_id, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
        )
        placement = data.oMf[self.frame_id]
        error = self.errors(np.array(placement.translation), np.array(placement.rotation))
        rows = {"position": jacobian[:3], "orientation": jacobian[3:]}
        names = {"position": ("x", "y", "z"), "orientation": ("rx", "ry", "rz")}
        return TaskRows(
            np.vstack([rows[c] for c in self.components]),
            self.gain * error,
            describe=lambda: tuple(n for c in self.components for n in names[c]),
        )

    def deviation(self, samples: Samples) -> Deviation:
        """:meth:`errors` at every sample (m, rad)."""
        values = np.array([self.errors(*self.pose(q)) for q in samples.q])
        units = {"position": ("m",) * 3, "orientation": ("rad",) * 3}
        return Deviation(values, tuple(u for c in self.components for u in units[c]))


def _rotation(value: ArrayLike) -> NDArray[np.float64]:
    """A rotation matrix (3, 3): orthonormal to 1e-9, determinant +1."""
    r = np.array(value, dtype=np.float64)
    if r.shape != (3, 3) or not np.isfinite(r).all():
        raise ParameterError("rotation", f"expected a 3 x 3 rotation matrix, got shape {r.shape}")
    if not np.allclose(r @ r.T, np.eye(3), atol=1e-9) or np.linalg.det(r) < 0:
        raise ParameterError("rotation", "must be a rotation matrix (orthonormal, det +1)")
    return r
