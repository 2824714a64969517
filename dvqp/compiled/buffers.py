"""The arrays a compiled step reads and writes, and the kernel that fills them.

:class:`StateBuffers` hold one configuration's kinematics, :class:`ProximityBuffers` its
distances to an obstacle set, :class:`SelfPairBuffers` the self-collision pairs: each the
compiled counterpart of :class:`~dvqp.kinematics.state.KinematicState`,
:class:`~dvqp.geometry.proximity.Proximity` and the self-collision geometry, allocated once per
run by a :class:`~dvqp.compiled.plan.StepPlan` and overwritten in place per state.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]


@dataclass(frozen=True)
class Kernel:
    """A compiled function and its bound arguments: calling it is ``function(*args)``.

    ``args`` may hold :class:`Slot` placeholders (rows of the stacked ``G``/``h``/``A``/``b``
    or a slice of the verification values), replaced by array views in :meth:`StepPlan.bind`.
    Arguments are arrays (float64 of 1–3 dimensions, int64 vectors, bool matrices; C-contiguous
    so that :func:`~dvqp.compiled.fusion.fuse` can pack them) and Python scalars. A ``checked``
    kernel returns an int: −1 when all is well, anything else stops the sequence it runs in.
    """

    function: Callable[..., Any]
    args: tuple[Any, ...]
    checked: bool = False


@dataclass(frozen=True)
class Slot:
    """A placeholder for rows ``[start, stop)`` of one of the plan's stacked arrays."""

    array: str
    start: int
    stop: int


@dataclass(frozen=True)
class StateBuffers:
    """One configuration's kinematics, as :class:`~dvqp.kinematics.state.KinematicState` has it.

    Attributes (all float64, written in place once per state)
    ----------
    q : (n,)
        rad.
    origins, axes : (k+1, 3)
        Frame origins (m) and unit z axes of the k body points then the tool, base frame.
    frame_jacobians : (k+1, 6, n)
        ``[J_v; J_ω]``, base orientation (LOCAL_WORLD_ALIGNED).
    guarded : (k+1, 3)
        DV ``[l, z, h]`` (m) of the body points then the probe.
    guarded_jacobians : (k+1, 3, n)
        Their ``∂[l, z, h]/∂Q``.
    tool : (4,)
        ``[l, z, h, α]``.
    tool_jacobian : (4, n)
        ``J̄``.
    """

    q: Array
    origins: Array
    axes: Array
    frame_jacobians: Array
    guarded: Array
    guarded_jacobians: Array
    tool: Array
    tool_jacobian: Array

    @classmethod
    def allocate(cls, n: int, k: int) -> StateBuffers:
        """Zeroed buffers for n joints and k body points."""
        m = k + 1
        return cls(
            np.zeros(n),
            np.zeros((m, 3)),
            np.zeros((m, 3)),
            np.zeros((m, 6, n)),
            np.zeros((m, 3)),
            np.zeros((m, 3, n)),
            np.zeros(4),
            np.zeros((4, n)),
        )

    def load(self, state: Any) -> None:
        """Copy a :class:`~dvqp.kinematics.state.KinematicState` in (tests, fallbacks)."""
        for name in self.__dataclass_fields__:
            np.copyto(getattr(self, name), getattr(state, name))


@dataclass(frozen=True)
class ProximityBuffers:
    """Signed distances of the guarded parts to J obstacles, as
    :class:`~dvqp.geometry.proximity.Proximity` has them (rows in the obstacle set's order).

    Attributes
    ----------
    point_distance, point_penalty : (J, k+1)
    point_normal, point_penalty_gradient : (J, k+1, 2)
    link_distance, link_penalty, link_t : (J, k)
    link_normal, link_penalty_gradient : (J, k, 2)
    """

    point_distance: Array
    point_normal: Array
    point_penalty: Array
    point_penalty_gradient: Array
    link_distance: Array
    link_normal: Array
    link_penalty: Array
    link_penalty_gradient: Array
    link_t: Array

    @classmethod
    def allocate(cls, count: int, k: int) -> ProximityBuffers:
        """Zeroed buffers for ``count`` obstacles and k body points."""
        p, s = (count, k + 1), (count, k)
        return cls(
            np.zeros(p),
            np.zeros((*p, 2)),
            np.zeros(p),
            np.zeros((*p, 2)),
            np.zeros(s),
            np.zeros((*s, 2)),
            np.zeros(s),
            np.zeros((*s, 2)),
            np.zeros(s),
        )

    def load(self, proximity: Any) -> None:
        """Copy a :class:`~dvqp.geometry.proximity.Proximity` in (tests)."""
        for side in ("point", "link"):
            found = getattr(proximity, f"{side}s")
            for name in ("distance", "normal", "penalty", "penalty_gradient"):
                np.copyto(getattr(self, f"{side}_{name}"), getattr(found, name))
        np.copyto(self.link_t, proximity.links.t)


@dataclass(frozen=True)
class SelfPairBuffers:
    """The non-adjacent guarded link pairs ``(i, j)`` and their closest points, per state.

    Attributes
    ----------
    i, j : (P,) int64
        Link indices (constant).
    distance, s, t : (P,)
    normal : (P, 3)
        Unit ``c_i − c_j``.
    """

    i: NDArray[np.int64]
    j: NDArray[np.int64]
    distance: Array
    normal: Array
    s: Array
    t: Array
