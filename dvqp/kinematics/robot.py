"""The manipulator: a Pinocchio model with named body-point frames, a tool frame and limits.

A :class:`Robot` is built from a DH table (:meth:`Robot.from_dh`), from the paper's 13-DOF
arm (:meth:`Robot.ndt13`) or from a URDF file (:meth:`Robot.from_urdf`). The method is not
limited to 13 DOF: any serial chain with ``n`` revolute (or prismatic) joints, ``k`` point
frames and a tool frame works; a mimic joint follows its master (it adds no coordinate). The
pipe's frame is the model's world frame (its z axis the pipe axis); :meth:`Robot.placed` puts
the arm's base anywhere in it.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from pathlib import Path
from typing import Literal

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike, NDArray

from dvqp import _validate
from dvqp.errors import ParameterError
from dvqp.kinematics.dh import DHRow, check_transform, fixed_part, ndt13_table
from dvqp.kinematics.model import ModelArrays
from dvqp.kinematics.urdf import urdf_model
from dvqp.workspace import PartNames

NDT13_POINT_JOINTS = (4, 6, 8, 10, 13)
"""Joints (1-based) whose output frames are the paper's five body points."""
NDT13_RAIL_JOINT = 2
"""Joint (1-based) whose output frame is the rail point: ``d_2 = L1`` out from the pipe axis."""

DEFAULT_QD_MAX = 1.5
"""Default joint velocity limit, rad/s."""


class Robot:
    """A serial manipulator with body points, a tool frame and joint limits.

    Parameters
    ----------
    model
        Pinocchio model with ``nq == nv == n``: revolute and prismatic joints about fixed axes.
    point_frames
        Names of the body-point frames, in order along the chain (k >= 2).
    tool_frame
        Name of the tool frame (its z axis is the probe axis).
    rail_frame
        Name of the frame at the rail point, where the carriage rides its rail: the carriage
        link from it to the first body point is then guarded too. None: no such link.
    base_frame
        Name of the frame of the arm's base (a URDF's root link). Where the arm has no rail
        and its base stands off the pipe axis (an arm standing on the pipe, placed by
        :meth:`placed`), the base is guarded as the arm's lead point, with the base link from
        it to the first body point: every part from the base on is kept out of the pipe and
        the obstacles (:attr:`base_frame` is then that name, else None; a base that is itself
        a listed body point is guarded as one).
    q_min, q_max
        Joint position limits, rad, scalar or shape (n,); ``±inf`` for none.
        Default: the model's own limits.
    qd_max
        Joint velocity limits, rad/s, scalar or shape (n,), > 0.
    name
        A label for reports.
    names
        The guarded parts' names in labels and reports (default: dvqp's numbering,
        ``point1``, ``probe``, ``link1``, ``holder``, …; ``"frames"``, as :meth:`from_urdf`
        names them: the frames' own, :meth:`~dvqp.workspace.PartNames.of_frames`).
    """

    def __init__(
        self,
        model: pin.Model,
        point_frames: Sequence[str],
        tool_frame: str,
        *,
        rail_frame: str | None = None,
        base_frame: str | None = None,
        q_min: ArrayLike | None = None,
        q_max: ArrayLike | None = None,
        qd_max: ArrayLike = DEFAULT_QD_MAX,
        name: str = "robot",
        names: PartNames | Literal["frames"] | None = None,
    ) -> None:
        if model.nq != model.nv:
            raise ParameterError("model", "only joints with nq == nv (revolute, prismatic)")
        self.model, self.name, n = model, name, model.nq
        if len(point_frames) < 2:
            raise ParameterError("points", "need at least two body-point frames")
        self.point_frames, self.tool_frame = tuple(point_frames), tool_frame
        self.rail_frame = rail_frame
        self.root_frame = base_frame
        """The base frame's name as given (guarded or not: :attr:`base_frame`)."""
        standing = rail_frame is None and base_frame not in (*point_frames, tool_frame)
        self.base_frame = _standing_base(model, base_frame) if standing else None
        """The guarded base frame's name, or None (see the parameter)."""
        lead = rail_frame if rail_frame is not None else self.base_frame
        self.named_by_frames = names == "frames"
        if names is None:
            names = PartNames.numbered(len(point_frames), lead is not None)
        elif names == "frames":
            base = self.base_frame is not None
            names = PartNames.of_frames(point_frames, tool_frame, lead, base)
        self.part_names: PartNames = names
        """The guarded parts' names in labels and reports (:class:`~dvqp.workspace.PartNames`)."""
        if (names.k, names.rail, names.base) != (
            len(point_frames),
            lead is not None,
            self.base_frame is not None,
        ):
            raise ParameterError("names", "not the names of this arm's body points and rail")
        for fname in self.frame_names:
            if not model.existFrame(fname):
                known = ", ".join(f.name for f in model.frames)
                raise ParameterError("frames", f"no frame named {fname!r} (model has: {known})")
        self.frame_ids: tuple[int, ...] = tuple(map(model.getFrameId, self.frame_names))
        lo = model.lowerPositionLimit if q_min is None else q_min
        hi = model.upperPositionLimit if q_max is None else q_max
        self.q_min = _validate.readonly(_validate.limit("q_min", lo, n))
        self.q_max = _validate.readonly(_validate.limit("q_max", hi, n))
        if np.any(self.q_min > self.q_max):
            raise ParameterError("q_min", "must be <= q_max for every joint")
        qd = _validate.broadcast("qd_max", qd_max, n)
        if np.any(qd <= 0):
            raise ParameterError("qd_max", "must be > 0 for every joint")
        self.qd_max = _validate.readonly(qd)
        # refuses other joint types
        self._arrays = ModelArrays.of(model, self.frame_ids, len(self.point_frames))

    def model_arrays(self) -> ModelArrays:
        """The model's constants for the compiled kinematics, with scratch arrays of their own
        (each run or evaluation owns one)."""
        a = self._arrays
        return dataclasses.replace(a, work=np.zeros_like(a.work), world=np.zeros_like(a.world))

    @property
    def lead_frame(self) -> str | None:
        """The guarded frame before the first body point: the rail point's, the base's, or
        None."""
        return self.rail_frame if self.rail_frame is not None else self.base_frame

    @property
    def frame_names(self) -> tuple[str, ...]:
        """Names of the guarded frames: the body points, the tool, the lead point (if any)."""
        lead = () if self.lead_frame is None else (self.lead_frame,)
        return (*self.point_frames, self.tool_frame, *lead)

    @property
    def joint_names(self) -> tuple[str, ...]:
        """The names of the n joints that have a coordinate, in the order of ``q`` (a mimic
        joint has none: it follows its master)."""
        model = self.model
        joints = [
            (model.joints[j].idx_q, model.names[j])
            for j in range(1, model.njoints)
            if model.joints[j].nq > 0
        ]
        return tuple(name for _, name in sorted(joints))

    def placed(self, base: ArrayLike) -> Robot:
        """The same arm with its base frame at ``base`` (4, 4) in the pipe's frame: every joint
        and frame attached to the model's world frame moved by it (the URDF's root link and
        the first joints), nothing else changed (placing a placed arm moves it again:
        ``placed(a).placed(b)`` is ``placed(b @ a)``).

        Raises
        ------
        ParameterError
            ``base`` is not a rigid transform.
        """
        placement = pin.SE3(check_transform("base", base))
        model = pin.Model(self.model)
        for j in range(1, model.njoints):
            if model.parents[j] == 0:
                model.jointPlacements[j] = placement * model.jointPlacements[j]
        for f in range(len(model.frames)):
            frame = model.frames[f]
            if frame.parentJoint == 0 and frame.name != "universe":
                frame.placement = placement * frame.placement
                model.frames[f] = frame
        return Robot(
            model,
            self.point_frames,
            self.tool_frame,
            rail_frame=self.rail_frame,
            base_frame=self.root_frame,
            q_min=self.q_min,
            q_max=self.q_max,
            qd_max=self.qd_max,
            name=self.name,
            names="frames" if self.named_by_frames else self.part_names,
        )

    @property
    def has_rail(self) -> bool:
        """Whether the arm has a lead point, guarded with the lead link from it to body point
        1: the rail point and the carriage link, or the base and the base link."""
        return self.lead_frame is not None

    @property
    def n(self) -> int:
        """Number of joints."""
        return int(self.model.nq)

    @property
    def n_points(self) -> int:
        """Number of body points."""
        return len(self.point_frames)

    def check_q(self, q: ArrayLike, name: str = "q") -> NDArray[np.float64]:
        """Return ``q`` as a finite float vector of length :attr:`n`, or raise."""
        return _validate.vector(name, q, self.n)

    @classmethod
    def from_dh(
        cls,
        table: Sequence[DHRow],
        tool: ArrayLike,
        point_joints: Sequence[int],
        *,
        rail_joint: int | None = None,
        q_min: ArrayLike = -np.pi,
        q_max: ArrayLike = np.pi,
        qd_max: ArrayLike = DEFAULT_QD_MAX,
        name: str = "dh-robot",
    ) -> Robot:
        """Build a revolute chain from a standard DH table.

        Joint i is a revolute joint about its local z, placed after joint i−1's fixed part
        ``Tz(d)·Tx(a)·Rx(α)``. Frame ``"point{j}"`` sits at the output of the j-th joint in
        ``point_joints`` (1-based), frame ``"tool"`` at ``T_n^0 · tool``.

        Parameters
        ----------
        table
            DH rows, one per joint.
        tool
            ``T_e^n``, shape (4, 4).
        point_joints
            1-based joint indices whose output frames are the body points.
        rail_joint
            1-based joint whose output frame (``"rail"``) is the rail point, or None.
        q_min, q_max, qd_max
            Limits, see :class:`Robot`.
        """
        if len(table) < 1:
            raise ParameterError("table", "needs at least one DH row")
        n = len(table)
        tool_t = check_transform("tool", tool)
        for j in point_joints:
            if not 1 <= int(j) <= n:
                raise ParameterError("point_joints", f"joint {j} is not in 1..{n}")
        if rail_joint is not None and not 1 <= int(rail_joint) < min(point_joints):
            raise ParameterError(
                "rail_joint", f"joint {rail_joint} is not before the first body point's"
            )
        lo = _validate.limit("q_min", q_min, n)
        hi = _validate.limit("q_max", q_max, n)
        model = pin.Model()
        model.name = name
        parent = 0
        placement = pin.SE3.Identity()
        inf = np.array([np.inf])
        for i, row in enumerate(table):
            if row.theta_offset != 0.0:
                rz = pin.SE3(pin.rpy.rpyToMatrix(0.0, 0.0, row.theta_offset), np.zeros(3))
                placement = placement * rz
            parent = model.addJoint(
                parent,
                pin.JointModelRZ(),
                placement,
                f"joint{i + 1}",
                inf,
                inf,
                lo[i : i + 1],
                hi[i : i + 1],
            )
            model.addJointFrame(parent, -1)
            placement = pin.SE3(fixed_part(row))
            for k, j in enumerate(point_joints):
                if int(j) == i + 1:
                    model.addFrame(pin.Frame(f"point{k + 1}", parent, placement, pin.OP_FRAME))
            if rail_joint is not None and int(rail_joint) == i + 1:
                model.addFrame(pin.Frame("rail", parent, placement, pin.OP_FRAME))
        tool_placement = pin.SE3(fixed_part(table[-1]) @ tool_t)
        model.addFrame(pin.Frame("tool", parent, tool_placement, pin.OP_FRAME))
        points = [f"point{k + 1}" for k in range(len(point_joints))]
        rail = None if rail_joint is None else "rail"
        return cls(
            model, points, "tool", rail_frame=rail, q_min=lo, q_max=hi, qd_max=qd_max, name=name
        )

    @classmethod
    def ndt13(
        cls,
        link_lengths: ArrayLike,
        *,
        q_min: ArrayLike | None = None,
        q_max: ArrayLike | None = None,
        qd_max: ArrayLike = DEFAULT_QD_MAX,
    ) -> Robot:
        """The paper's 13-DOF NDT manipulator (Table I) with body points at joints 4–13 and
        its rail point (the carriage on the rail, radius ``L1``) at joint 2's output.

        Parameters
        ----------
        link_lengths
            ``[L1, …, L7]``, m.
        q_min, q_max
            Limits, rad. Default: the carriage (joint 1) is unlimited, the arm joints ±π.
        qd_max
            Velocity limits, rad/s.
        """
        table, tool = ndt13_table(link_lengths)
        default_lo = np.full(13, -np.pi)
        default_lo[0] = -np.inf
        lo = default_lo if q_min is None else q_min
        hi = -default_lo if q_max is None else q_max
        return cls.from_dh(
            table,
            tool,
            NDT13_POINT_JOINTS,
            rail_joint=NDT13_RAIL_JOINT,
            q_min=lo,
            q_max=hi,
            qd_max=qd_max,
            name="ndt13",
        )

    @classmethod
    def from_urdf(
        cls,
        path: str | Path,
        points: Sequence[str],
        tool: str,
        *,
        rail: str | None = None,
        base: ArrayLike | None = None,
        q_min: ArrayLike | None = None,
        q_max: ArrayLike | None = None,
        qd_max: ArrayLike | None = None,
    ) -> Robot:
        """Load a serial arm from a URDF file; ``points``, ``tool`` and ``rail`` (optional: the
        rail point, see :class:`Robot`) are frame (link) names, and name the guarded parts in
        reports (:meth:`~dvqp.workspace.PartNames.of_frames`).

        The URDF's base frame is the pipe's frame (its z axis the pipe axis) unless ``base``
        places it (:meth:`placed`); an arm without a rail placed off the pipe axis stands on
        the pipe, and its base (the root link) is guarded from there on (``base_frame``).
        ``continuous`` joints become revolute joints without position limits (``±inf``);
        ``revolute`` and ``prismatic`` joints keep their limits. A joint with a ``<mimic>``
        follows its master, ``multiplier · q + offset``, with no
        coordinate of its own (Pinocchio's mimic joints): its master's limits are narrowed to
        keep it within its own. Velocity limits default to the URDF's, or
        :data:`DEFAULT_QD_MAX` where it gives none. The file is checked before Pinocchio's
        parser sees it (:func:`~dvqp.kinematics.urdf_check.read_urdf`: size, one tree of
        links, joint types and counts, names, numbers); what the C++ parser prints is kept off
        the terminal, its first complaint is part of the error.

        Parameters
        ----------
        base
            The URDF's base frame in the pipe's frame, (4, 4) (translation in m); None: the
            same frame.

        Raises
        ------
        RobotFileError
            ``<path>: <reason>``: a file the checks refuse, or ``<path>: cannot load URDF:
            <reason>`` one the parser refuses.
        ParameterError
            ``frames``: no such frame; ``base``: not a rigid transform.
        """
        model = urdf_model(path)
        if qd_max is None:
            vel = np.asarray(model.velocityLimit, dtype=float)
            qd_max = np.where(np.isfinite(vel) & (vel > 0), vel, DEFAULT_QD_MAX)
        robot = cls(
            model,
            points,
            tool,
            rail_frame=rail,
            base_frame=root_frame(model),
            q_min=q_min,
            q_max=q_max,
            qd_max=qd_max,
            name=model.name,
            names="frames",
        )
        return robot if base is None else robot.placed(base)


def root_frame(model: pin.Model) -> str | None:
    """The name of the model's root link frame (a URDF's base link: the first body frame on
    the world), or None."""
    for frame in model.frames:
        if frame.parentJoint == 0 and frame.type == pin.FrameType.BODY:
            return str(frame.name)
    return None


def _standing_base(model: pin.Model, frame: str | None) -> str | None:
    """``frame`` if the arm's base stands off the pipe axis (its origin farther than 1 µm from
    it: an arm on the pipe, not one whose base is the pipe's own frame), else None."""
    if frame is None or not model.existFrame(frame):
        return None
    x, y = model.frames[model.getFrameId(frame)].placement.translation[:2]
    return frame if float(np.hypot(x, y)) > 1e-6 else None
