"""A planned run retimed for a controller: the same path, as fast as the joints allow.

:func:`retime` parameterises the planned path in time (:mod:`dvqp.retime.parameterise`:
toppra, under every joint's ``qd_max`` and ``qdd_max``, from rest to rest), samples it at the
controller's rate and verifies every sample exactly against every limit of the run's step, as
a planned step is verified (:class:`~dvqp.step.Stepper`, and
:func:`~dvqp.step.straight_excess` along the straight motion between two samples far apart).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from dvqp._files import atomic_file, output_path
from dvqp._versions import versions
from dvqp.errors import RetimingError
from dvqp.kinematics.robot import Robot
from dvqp.limits import NO_EXCESS, AccelerationLimit, Excess
from dvqp.resolution.pinv import PseudoinverseResolver
from dvqp.resolution.spec import StepSpec
from dvqp.retime.joint_trajectory import joint_trajectory
from dvqp.retime.parameterise import parameterise
from dvqp.step import Stepper, straight_excess
from dvqp.step.advance import SINGULAR

Array = NDArray[np.float64]

DEFAULT_RATE = 500.0
"""Hz: the controller rate a motion is sampled at unless told otherwise."""
MOST_OF_THE_PATH = 0.5
"""A retimed motion whose samples trace less than this share of the planned path
(:func:`traced_share`) :attr:`~Retimed.drops_path` (``dvqp plan --retime`` warns)."""
FORMATS = (".npz", ".csv", ".json")
"""What :meth:`Retimed.save` writes (``.json``: a ROS ``trajectory_msgs/JointTrajectory``)."""


class RunScene(Protocol):
    """What retiming needs of a scene (:class:`dvqp.Scene` has it): the arm, the pipe and
    the step whose limits the retimed samples are verified against."""

    robot: Robot
    pipe_radius: float

    def spec(self) -> StepSpec: ...


@dataclass(frozen=True)
class Retimed:
    """A retimed motion: samples ``j = 0..M−1`` every ``1 / rate`` s, at rest at both ends.

    Attributes
    ----------
    t : ndarray, shape (M,)
        Time from the start, s (``j / rate``).
    q, qdot, qddot : ndarray, shape (M, n)
        Joint positions, velocities and accelerations at each sample, rad, rad/s, rad/s²
        (``qdot`` is 0 at the first and the last sample).
    joint_names : tuple of str
        The arm's joints, in the order of the columns (the rail joint first).
    rate, planned_duration : float
        The controller rate, Hz, and the duration of the planned run, s.
    velocity_use, acceleration_use : float
        The largest ``|q̇| / q̇_max`` and ``|q̈| / q̈_max`` over the samples and joints (<= 1).
    excess : Excess
        The worst exact excess of any limit of the step over the samples and the straight
        motions between them, against ``min(bound, value at the planned start)`` as in the
        planned run (:data:`~dvqp.limits.NO_EXCESS`: nothing to verify).
    path_share : float
        How much of the planned path the samples trace (:func:`traced_share`: each joint's
        travel along them over its planned travel, averaged; 1: all of it). Below
        :data:`MOST_OF_THE_PATH` the rate is too low for the path (:attr:`drops_path`).
    """

    t: Array
    q: Array
    qdot: Array
    qddot: Array
    joint_names: tuple[str, ...]
    rate: float
    planned_duration: float
    velocity_use: float
    acceleration_use: float
    excess: Excess = NO_EXCESS
    path_share: float = 1.0

    @property
    def drops_path(self) -> bool:
        """The samples miss most of the planned path (:attr:`path_share` below
        :data:`MOST_OF_THE_PATH`): a controller going straight from one to the next would
        not follow it; a higher rate would."""
        return self.path_share < MOST_OF_THE_PATH

    @property
    def duration(self) -> float:
        """The retimed motion's duration, s."""
        return float(self.t[-1])

    @property
    def kept(self) -> bool:
        """Every sample keeps every limit: exactly checked ones to their tolerance, the joint
        velocity and acceleration limits with no tolerance."""
        return not self.excess.broken and max(self.velocity_use, self.acceleration_use) <= 1.0

    def summary(self) -> str:
        """``2.31 s (planned 4.00 s), 1156 samples at 500 Hz, limits kept`` (or the limit
        broken)."""
        kept = "limits kept" if self.kept else f"BROKEN: {self.excess.describe()}"
        return (
            f"{self.duration:.2f} s (planned {self.planned_duration:.2f} s), "
            f"{self.t.shape[0]} samples at {self.rate:g} Hz, {kept}"
        )

    def save(self, path: str | Path) -> Path:
        """Write the samples atomically: ``.npz`` (``t``, ``q``, ``qdot``, ``qddot``,
        ``joint_names``, ``rate``, ``planned_duration`` and ``meta``, a JSON text of the
        versions and units), ``.csv`` (one row a sample: ``t, q1..qn, qdot1..qdotn,
        qddot1..qddotn``) or ``.json`` (a ROS ``trajectory_msgs/JointTrajectory``,
        :func:`~dvqp.retime.joint_trajectory.joint_trajectory`)."""
        target = output_path(path, FORMATS)
        suffix = target.suffix.lower()
        with atomic_file(target) as tmp, open(tmp, "wb") as fh:
            if suffix == ".json":
                doc = joint_trajectory(self.joint_names, self.t, self.q, self.qdot, self.qddot)
                fh.write(json.dumps(doc, allow_nan=False).encode("utf-8"))
            elif suffix == ".csv":
                n = self.q.shape[1]
                header = [
                    "t",
                    *(f"{name}{i + 1}" for name in ("q", "qdot", "qddot") for i in range(n)),
                ]
                table = np.column_stack([self.t, self.q, self.qdot, self.qddot])
                np.savetxt(
                    fh, table, delimiter=",", header=",".join(header), comments="", fmt="%.17g"
                )
            else:
                meta = {"versions": versions(), "units": "s, rad, rad/s, rad/s^2; rate in Hz"}
                np.savez_compressed(
                    fh,
                    t=self.t,
                    q=self.q,
                    qdot=self.qdot,
                    qddot=self.qddot,
                    joint_names=np.array(self.joint_names, dtype=np.str_),
                    rate=np.float64(self.rate),
                    planned_duration=np.float64(self.planned_duration),
                    meta=np.str_(json.dumps(meta)),
                )
        return target


def retime(scene: RunScene, q: ArrayLike, t: ArrayLike, rate: float = DEFAULT_RATE) -> Retimed:
    """The planned samples ``q`` (N+1, n), rad, at times ``t`` (N+1,), s, retimed: the fastest
    motion along their path within the arm's ``qd_max`` and the step's ``qdd_max``, from rest
    to rest, sampled at ``rate`` Hz, every sample verified exactly against the scene's limits
    (:attr:`Retimed.kept` says whether it keeps them all).

    Raises
    ------
    ParameterError
        ``rate`` is not a number > 0, or gives too many samples.
    RetimingError
        The path does not move, no motion along it keeps the limits, the step has no
        acceleration limit, or toppra is not installed.
    """
    robot, spec = scene.robot, scene.spec()
    accelerations = [lim for lim in spec.limits if isinstance(lim, AccelerationLimit)]
    if not accelerations:
        raise RetimingError("the step has no acceleration limit: nothing bounds the retiming")
    qdd_max = accelerations[0].qdd_max
    q, t = np.asarray(q, dtype=float), np.asarray(t, dtype=float)
    samples = parameterise(q, t, robot.qd_max, qdd_max, rate)
    return Retimed(
        samples.t,
        samples.q,
        samples.qdot,
        samples.qddot,
        joint_names=robot.joint_names,
        rate=float(rate),
        planned_duration=float(t[-1] - t[0]),
        velocity_use=float(np.max(np.abs(samples.qdot) / robot.qd_max)),
        acceleration_use=float(np.max(np.abs(samples.qddot) / qdd_max)),
        excess=verified(scene, spec, q[0], samples.q),
        path_share=traced_share(q, samples.q),
    )


def traced_share(planned: Array, samples: Array) -> float:
    """How much of the planned path the polyline through ``samples`` (M, n) traces: each
    moving joint's travel (the sum of its steps' sizes) along the samples over its travel
    along the ``planned`` ones (N+1, n), at most 1, averaged over the joints that move (1 if
    none does). Samples that skip a joint's back and forth trace little of it."""
    travel = np.abs(np.diff(planned, axis=0)).sum(axis=0)
    moving = travel > 0.0
    if not moving.any():
        return 1.0
    traced = np.abs(np.diff(samples, axis=0)).sum(axis=0)
    return float(np.mean(np.minimum(1.0, traced[moving] / travel[moving])))


def verified(scene: RunScene, spec: StepSpec, q0: Array, samples: Array) -> Excess:
    """The worst exact excess of the step's limits over ``samples`` (M, n) and the straight
    motions between consecutive ones (:func:`~dvqp.step.straight_excess`), the floors set at
    the planned start ``q0`` (:data:`SINGULAR` if a sample puts a guarded frame on the pipe
    axis)."""
    stepper = Stepper(scene.robot, scene.pipe_radius, PseudoinverseResolver(spec), q0, 1.0)
    stepper.start(q0)
    worst, worst_ratio, worst_at = NO_EXCESS, -np.inf, -1
    for j in range(samples.shape[0]):
        between = straight_excess(stepper, samples[j - 1], samples[j]) if j else NO_EXCESS
        if between.ratio > worst_ratio:
            worst, worst_ratio, worst_at = between, between.ratio, -1
        if not stepper.load(samples[j]):
            return SINGULAR
        ratio = float(stepper.excess_now[1])
        if not ratio <= worst_ratio:  # NaN too: the worst
            worst_ratio, worst_at = ratio if ratio == ratio else np.inf, j
    if worst_at >= 0:
        stepper.load(samples[worst_at])
        worst = stepper.excess()
    return worst
