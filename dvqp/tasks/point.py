"""Hold a body point of the arm at a place in the developed view: some of its ``[l, z, h]``."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from dvqp import _validate
from dvqp.errors import ParameterError
from dvqp.kinematics.developed_view import wrap, wrap_period
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
from dvqp.workspace.wiring import StepWiring, overrides
from solvers.jit import njit

COMPONENTS = ("l", "z", "h")
"""A body point's developed-view coordinates (m), in the order of its Jacobian's rows."""


class PointTask(Task):
    """``J_p,c Q̇ = K (p*_c − p_c)``: body point ``point`` moves toward its target ``p*`` in the
    ``components`` chosen (l differences wrapped round the pipe).

    ``J_p = ∂[l, z, h]/∂Q`` of the point (:attr:`KinematicState.point_jacobians`). A hard
    task, compiled (:func:`point_rows`), at its ``priority``.

    Parameters
    ----------
    point
        The body point: its index, 0-based (0 .. k − 1), or its name as reports and plots
        give it, ``"point3"`` (1-based: index 2).
    components
        A non-empty subset of ``("l", "z", "h")``.
    target
        ``[l, z, h]`` (m, shape (3,); only the chosen components are read), or one number per
        chosen component (``PointTask(2, ("h",), [0.07])``, as a scene file takes it). None:
        where the point is when the run starts (the state the step is laid out at).
    gain
        ``K``, 1/s, >= 0.
    priority, weight
        As every task's (:class:`~dvqp.tasks.Task`).

    Raises
    ------
    ParameterError
        A negative point index or a name not ``"point<k>"``, an empty, unknown or repeated
        component, a target not of 3 (or one per component) finite numbers, a gain < 0, a
        priority not an integer >= 1, a weight not > 0. A point index beyond the arm's points
        is refused when the task joins a run.
    """

    name = "point"
    hard = True

    def __init__(
        self,
        point: int,
        components: Sequence[str] = COMPONENTS,
        target: ArrayLike | None = None,
        *,
        gain: float = DEFAULT_GAIN,
        priority: int = 1,
        weight: float = 1.0,
    ) -> None:
        self.point = point_index(point)
        self.components = check_components("components", components, COMPONENTS)
        self.target = None if target is None else _validate.readonly(self._full(target))
        self.gain = _validate.positive("gain", gain, strict=False)
        self.priority = check_priority(priority)
        self.weight = check_weight(weight)

    def _full(self, target: ArrayLike) -> NDArray[np.float64]:
        """``target`` as ``[l, z, h]`` (3,): given so, or one number per chosen component (the
        others, never read, 0)."""
        m = len(self.components)
        size = np.size(target)
        if m < 3 and size == m:
            full = np.zeros(3)
            full[self.index] = _validate.vector("target", target, m)
            return full
        return _validate.vector("target", target, 3)

    def __repr__(self) -> str:
        return f"PointTask({self.point}, {self.components!r}, priority={self.priority})"

    @property
    def label(self) -> str:
        """``"point2 h"``: the point (1-based, as reports name body points) and components."""
        return f"point{self.point + 1} {', '.join(self.components)}"

    @property
    def index(self) -> NDArray[np.int64]:
        """The components' rows (0 l, 1 z, 2 h), shape (m,)."""
        return np.array([COMPONENTS.index(c) for c in self.components], dtype=np.int64)

    def check(self, k: int) -> None:
        """Refuse a point index beyond ``k`` body points."""
        if self.point >= k:
            raise ParameterError(
                "point", f"index {self.point} is out of range: the arm has body points 0 .. {k - 1}"
            )

    def goal(self, state: KinematicState) -> NDArray[np.float64]:
        """The target, or (None) the point where it is at ``state``, m, shape (3,)."""
        self.check(state.k)
        return np.array(state.points[self.point] if self.target is None else self.target)

    def compute(self, state: KinematicState, command: NDArray[np.float64], dt: float) -> TaskRows:
        """The rows :func:`point_rows` writes toward :meth:`goal` at ``state`` (without a
        target: the point held where it is, ``v = 0``)."""
        index, goal = self.index, self.goal(state)
        m = index.shape[0]
        jacobian, velocity = np.zeros((m, state.n)), np.zeros(m)
        period = 2.0 * math.pi * state.radius
        point_rows(
            state.guarded,
            state.guarded_jacobians,
            self.point,
            index,
            goal,
            self.gain,
            period,
            jacobian,
            velocity,
            0,
        )
        return TaskRows(jacobian, velocity, describe=lambda: self.components)

    def deviation(self, samples: Samples) -> Deviation:
        """``p*_c − p_c`` at every sample (l wrapped), m; without a target, against the first
        sample's point (the run's start)."""
        points = samples.points[:, self.point, :]
        goal = points[0] if self.target is None else self.target
        error = goal[None, :] - points
        error[:, 0] = wrap(error[:, 0], samples.radius)
        index = self.index
        return Deviation(error[:, index], ("m",) * index.shape[0])

    def join(self, step: StepWiring) -> None:
        """Rows of the hard tasks, written by :func:`point_rows`: the entry
        ``[first row, count, point, c0 .. c2]`` with its target (3,) and gain."""
        if overrides(self, PointTask, "compute", "kernel") or not self.hard:
            return super().join(step)
        self.check(step.plan.k)
        index = self.index
        goal = self.goal(step.start)
        start = step.plan.task_rows(index.shape[0])[0].start
        padded = np.full(3, -1, np.int64)
        padded[: index.shape[0]] = index
        step.tasks["point"].append(((start, index.shape[0], self.point, *padded), goal, self.gain))
        return None


def point_index(point: object, names: Sequence[str] = ()) -> int:
    """A body point's 0-based index from ``point``: an integer >= 0, or a name, ``"point3"``
    (dvqp's numbering, 1-based, as reports name body points) or one of ``names`` (the arm's
    body points as its reports name them: a URDF arm's frames).

    Raises
    ------
    ParameterError
        Anything else.
    """
    if isinstance(point, str):
        if point in names:
            return list(names).index(point)
        number = point.removeprefix("point")
        if point.startswith("point") and number.isdigit() and int(number) >= 1:
            return int(number) - 1
        known = f" or one of {', '.join(names)}" if names else ""
        raise ParameterError(
            "point", f"unknown body point {point!r} (names: point1, point2, …{known})"
        )
    if isinstance(point, bool) or not isinstance(point, (int, np.integer)) or point < 0:
        raise ParameterError(
            "point", f'must be an integer >= 0 or a name ("point3"), got {point!r}'
        )
    return int(point)


@njit(separate=True)
def point_rows(
    guarded: NDArray[np.float64],
    guarded_jacobians: NDArray[np.float64],
    point: int,
    components: NDArray[np.int64],
    target: NDArray[np.float64],
    gain: float,
    period: float,
    A: NDArray[np.float64],
    b: NDArray[np.float64],
    start: int,
) -> None:
    """Rows ``start ..`` of ``A``, ``b``: ``∂p_c/∂Q`` of guarded point ``point`` and
    ``gain · (target_c − p_c)`` (an l difference wrapped into one ``period``, m)."""
    for i in range(components.shape[0]):
        c = components[i]
        d = target[c] - guarded[point, c]
        if c == 0:
            d = wrap_period(d, period)
        b[start + i] = gain * d
        for j in range(A.shape[1]):
            A[start + i, j] = guarded_jacobians[point, c, j]
