"""The kinematics of one configuration, as every other computation reads it.

A :class:`KinematicState` holds the frames, frame Jacobians and developed-view coordinates of
the body points and the tool. A run's state is a read-only view of its step's buffers
(:meth:`KinematicState.view`: it changes as the run moves on, as pink's ``Configuration``
does); :meth:`KinematicState.compute` evaluates one configuration on its own, with the same
compiled kinematics (:func:`dvqp.kinematics.model.kinematics`), into arrays of its own.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from dvqp import _validate
from dvqp.errors import SingularConfigurationError
from dvqp.kinematics.model import kinematics
from dvqp.kinematics.robot import Robot
from dvqp.workspace import StateBuffers, as_struct


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
        LOCAL_WORLD_ALIGNED): ``ȯ = J_v Q̇``, ``ω = J_ω Q̇``.
    guarded : ndarray, shape (k+1, 3)
        DV positions ``[l, z, h]`` (m) of every guarded point: the k body points, then the
        probe (the tool point). Consecutive points bound the guarded links: the k−1 body links,
        then the probe holder (last body point to the tool).
    guarded_jacobians : ndarray, shape (k+1, 3, n)
        ``∂[l, z, h]/∂Q`` of the same points, m/rad.
    points, point_jacobians : ndarray, shapes (k, 3), (k, 3, n)
        The body points alone: ``guarded[:-1]``, ``guarded_jacobians[:-1]``.
    tool : ndarray, shape (4,)
        Tool DV coordinates ``[l, z, h, α]`` (m, m, m, rad).
    tool_jacobian : ndarray, shape (4, n)
        The DV task Jacobian ``J̄(Q)``.
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

    @property
    def n(self) -> int:
        """Number of joints."""
        return int(self.q.shape[0])

    @property
    def k(self) -> int:
        """Number of body points."""
        return int(self.points.shape[0])

    @classmethod
    def view(cls, buffers: StateBuffers, radius: float) -> KinematicState:
        """Read-only views of ``buffers``: they show whatever state the buffers hold now."""
        views = {}
        for name in ("q", "origins", "axes", "frame_jacobians", "guarded", "guarded_jacobians",
                     "tool", "tool_jacobian"):  # fmt: skip
            views[name] = getattr(buffers, name).view()
            views[name].flags.writeable = False
        g, gj = views["guarded"], views["guarded_jacobians"]
        return cls(radius=float(radius), points=g[:-1], point_jacobians=gj[:-1], **views)

    @classmethod
    def compute(cls, robot: Robot, q: ArrayLike, radius: float) -> KinematicState:
        """The kinematics of ``q`` (rad, shape (n,)) in a pipe of ``radius`` (m).

        Raises
        ------
        ShapeError, ParameterError
            ``q`` has the wrong length or is not finite; ``radius`` is not > 0.
        SingularConfigurationError
            A body point or the tool lies on the pipe axis.
        """
        buffers = StateBuffers.allocate(robot.n, robot.n_points)
        buffers.q[:] = robot.check_q(q)
        r = _validate.positive("radius", radius)
        singular = kinematics(as_struct(robot.model_arrays()), r, as_struct(buffers))
        if singular != -1:
            raise singular_frame(robot, int(singular), buffers.origins[singular], buffers.q.copy())
        return cls.view(buffers, r)


def singular_frame(
    robot: Robot, frame: int, origin: NDArray[np.float64], q: object = None
) -> SingularConfigurationError:
    """The error of guarded frame ``frame`` found on the pipe axis (at ``origin``, m)."""
    rho = float(np.hypot(origin[0], origin[1]))
    name = robot.frame_names[frame]
    return SingularConfigurationError(
        f"frame {name!r} lies on the pipe axis (rho = {rho:.3g} m)", q
    )
