"""Where the arm is relative to the obstacles, computed once per state and shared.

The objective's obstacle terms, the QP's dampers and the clearance diagnostic all need the
signed distances of the guarded parts to every obstacle: the k body points and the probe (the
tool point), the k−1 body links and the probe holder (last body point to the tool).
:func:`proximity` computes them once for a :class:`~dvqp.kinematics.state.KinematicState` and
an :class:`ObstacleSet` and caches the result on the state, so each step does that geometry
once.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from dvqp.geometry.obstacle import ObstacleSet
from dvqp.geometry.shapes import ShapeDistances
from dvqp.kinematics.state import KinematicState


@dataclass(frozen=True)
class Proximity:
    """Signed distances of the k+1 guarded points and k guarded links to J obstacles.

    Index i < k is body point i+1, i = k the probe; link i < k−1 is body link i+1, link k−1
    the probe holder (see :func:`point_label`, :func:`link_label`).

    Attributes
    ----------
    points : ShapeDistances
        Arrays (J, k+1, ...): distance, normal ``∇_p d``, penalty and its gradient.
    links : ShapeDistances
        Arrays (J, k, ...), at each link's closest point ``p̄ = p_i + t (p_{i+1} − p_i)``.
    """

    points: ShapeDistances
    links: ShapeDistances

    @property
    def point_clearance(self) -> NDArray[np.float64]:
        """Signed clearance of each guarded point to each obstacle, m, shape (J, k+1)."""
        return self.points.distance

    @property
    def link_clearance(self) -> NDArray[np.float64]:
        """Signed clearance of each guarded link to each obstacle, m, shape (J, k)."""
        return self.links.distance

    @property
    def link_t(self) -> NDArray[np.float64]:
        """Parameter in [0, 1] of each link's closest point, shape (J, k)."""
        return self.links.t

    def min_clearance(self) -> float:
        """Smallest clearance of any guarded point or link, m (``inf`` with no obstacle)."""
        if self.points.distance.shape[0] == 0:
            return math.inf
        return float(min(self.point_clearance.min(), self.link_clearance.min()))

    def probe_clearance(self) -> float:
        """Smallest clearance of the probe and its holder, m (``inf`` with no obstacle)."""
        if self.points.distance.shape[0] == 0:
            return math.inf
        return float(min(self.point_clearance[:, -1].min(), self.link_clearance[:, -1].min()))

    def closest(self) -> tuple[float, str, int]:
        """The smallest clearance (m), the part that has it and the obstacle's index.

        Raises ValueError with no obstacle.
        """
        points, links = self.point_clearance, self.link_clearance
        k = points.shape[1] - 1
        j, i = np.unravel_index(int(np.argmin(points)), points.shape)
        lj, li = np.unravel_index(int(np.argmin(links)), links.shape)
        if links[lj, li] < points[j, i]:
            return float(links[lj, li]), link_label(int(li), k), int(lj)
        return float(points[j, i]), point_label(int(i), k), int(j)


def point_label(i: int, k: int) -> str:
    """Name of guarded point i (0-based) of a body with k points: ``"point3"`` or ``"probe"``."""
    return "probe" if i == k else f"point{i + 1}"


def link_label(i: int, k: int) -> str:
    """Name of guarded link i (0-based) of a body with k points: ``"link2"`` or ``"holder"``."""
    return "holder" if i == k - 1 else f"link{i + 1}"


def proximity(state: KinematicState, obstacles: ObstacleSet) -> Proximity:
    """The :class:`Proximity` of ``state`` to ``obstacles``, computed once and cached."""
    cache = state.cache
    found = cache.get(obstacles)
    if found is not None:
        return found  # type: ignore[no-any-return]
    lz = state.guarded[:, :2]
    period = 2.0 * np.pi * state.radius
    result = Proximity(obstacles.points(lz, period), obstacles.segments(lz[:-1], lz[1:], period))
    cache[obstacles] = result
    return result


def min_clearance(state: KinematicState, obstacles: ObstacleSet) -> float:
    """Smallest signed clearance (m) of any guarded part to ``obstacles``.

    Negative inside an obstacle; ``inf`` with no obstacles.
    """
    if not len(obstacles):
        return math.inf
    return proximity(state, obstacles).min_clearance()
