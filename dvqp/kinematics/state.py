"""The kinematics of one configuration, as every other computation reads it.

A :class:`KinematicState` holds the frames, frame Jacobians and developed-view coordinates of
the body points and the tool. A run's state is a read-only view of its step's buffers
(:meth:`KinematicState.view`: it changes as the run moves on, as pink's ``Configuration``
does); :meth:`KinematicState.compute` evaluates one configuration on its own, with the same
compiled kinematics (:func:`dvqp.kinematics.model.kinematics`), into arrays of its own.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from dvqp import _validate
from dvqp.errors import SingularConfigurationError
from dvqp.kinematics.model import kinematics
from dvqp.kinematics.robot import Robot
from dvqp.workspace import PartNames, StateBuffers, as_struct


@dataclass(frozen=True)
class KinematicState(StateBuffers):
    """Kinematics of one configuration in Cartesian and developed-view coordinates: the fields
    of :class:`~dvqp.workspace.StateBuffers` (``q``, ``origins``, ``axes``,
    ``frame_jacobians``, ``guarded``, ``guarded_jacobians``, ``tool``, ``tool_jacobian``) and
    the pipe's ``radius`` (m), the number ``k`` of body points and the guarded parts' ``names``
    (None: dvqp's numbering; see :attr:`part_names`).

    The guarded points are the k body points, the probe (the tool point, index k) and, if the
    arm has one, the rail point (index k + 1); the guarded links are the k−1 body links, the
    probe holder and the carriage link (rail point to body point 1; see
    :func:`dvqp.workspace.link_ends`). With ``frame_jacobians = [J_v; J_ω]`` (base
    orientation): ``ȯ = J_v Q̇``, ``ω = J_ω Q̇``.
    """

    radius: float = 0.0
    k: int = 0
    names: PartNames | None = None

    @property
    def part_names(self) -> PartNames:
        """The guarded parts' names in labels: the robot's, or dvqp's numbering."""
        return PartNames.numbered(self.k, self.rail) if self.names is None else self.names

    @property
    def points(self) -> NDArray[np.float64]:
        """Body points ``[l, z, h]`` (m), shape (k, 3): ``guarded[:k]``."""
        return self.guarded[: self.k]

    @property
    def point_jacobians(self) -> NDArray[np.float64]:
        """Their ``∂[l, z, h]/∂Q``, shape (k, 3, n): ``guarded_jacobians[:k]``."""
        return self.guarded_jacobians[: self.k]

    @property
    def n(self) -> int:
        """Number of joints."""
        return int(self.q.shape[0])

    @property
    def rail(self) -> bool:
        """Whether the rail point (and with it the carriage link) is guarded."""
        return int(self.guarded.shape[0]) > self.k + 1

    @classmethod
    def view(
        cls,
        buffers: StateBuffers,
        radius: float,
        k: int | None = None,
        names: PartNames | None = None,
    ) -> KinematicState:
        """Read-only views of ``buffers`` (k body points; default: every guarded point but the
        last, the tool; ``names`` their names): they show whatever state the buffers hold
        now."""
        views = {f.name: getattr(buffers, f.name).view() for f in dataclasses.fields(StateBuffers)}
        for view in views.values():
            view.flags.writeable = False
        points = int(buffers.guarded.shape[0]) - 1 if k is None else int(k)
        return cls(radius=float(radius), k=points, names=names, **views)

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
        buffers = StateBuffers.allocate(robot.n, robot.n_points, robot.has_rail)
        buffers.q[:] = robot.check_q(q)
        r = _validate.positive("radius", radius)
        singular = kinematics(as_struct(robot.model_arrays()), r, as_struct(buffers))
        if singular != -1:
            raise singular_frame(robot, int(singular), buffers.origins[singular], buffers.q.copy())
        return cls.view(buffers, r, robot.n_points, robot.part_names)


def singular_frame(
    robot: Robot, frame: int, origin: NDArray[np.float64], q: object = None
) -> SingularConfigurationError:
    """The error of guarded frame ``frame`` found on the pipe axis (at ``origin``, m)."""
    rho = float(np.hypot(origin[0], origin[1]))
    where = f"frame {robot.frame_names[frame]!r} lies on the pipe axis (rho = {rho:.3g} m)"
    return SingularConfigurationError(where, q)
