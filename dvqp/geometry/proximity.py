"""Where the body is relative to the obstacles, computed once per state and shared.

The objective's obstacle terms, the QP's dampers and the clearance diagnostic all need the
offsets of the guarded parts to every obstacle circle: the k body points and the probe (the
tool point), the k−1 body links and the probe holder (last body point to the tool).
:func:`proximity` computes them once for a :class:`~dvqp.kinematics.state.KinematicState` and an
:class:`ObstacleSet` and caches the result on the state, so each step does that geometry once.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from dvqp.geometry.obstacle import ObstacleSet, offsets
from dvqp.kinematics.developed_view import wrap
from dvqp.kinematics.state import KinematicState


@dataclass(frozen=True)
class Proximity:
    """Offsets of the k+1 guarded points and k guarded links to J obstacles (l wrapped).

    Index i < k is body point i+1, i = k the probe; link i < k−1 is body link i+1, link k−1
    the probe holder (see :func:`point_label`, :func:`link_label`).

    Attributes
    ----------
    point_offsets : ndarray, shape (J, k+1, 2)
        ``S_j − p_i``, m.
    point_distance : ndarray, shape (J, k+1)
        ``‖S_j − p_i‖``, m.
    link_t : ndarray, shape (J, k)
        Parameter in [0, 1] of the closest point ``p̄`` of link i to centre j.
    link_offsets : ndarray, shape (J, k, 2)
        ``S_j − p̄``, m.
    link_distance : ndarray, shape (J, k)
        ``‖S_j − p̄‖``, m.
    radii : ndarray, shape (J,)
        Obstacle radii, m.
    """

    point_offsets: NDArray[np.float64]
    point_distance: NDArray[np.float64]
    link_t: NDArray[np.float64]
    link_offsets: NDArray[np.float64]
    link_distance: NDArray[np.float64]
    radii: NDArray[np.float64]

    @property
    def point_clearance(self) -> NDArray[np.float64]:
        """Signed clearance of each guarded point to each circle, m, shape (J, k+1)."""
        return self.point_distance - self.radii[:, None]

    @property
    def link_clearance(self) -> NDArray[np.float64]:
        """Signed clearance of each guarded link to each circle, m, shape (J, k)."""
        return self.link_distance - self.radii[:, None]

    def min_clearance(self) -> float:
        """Smallest clearance of any guarded point or link, m (``inf`` with no obstacle)."""
        if self.radii.shape[0] == 0:
            return float("inf")
        return float(min(self.point_clearance.min(), self.link_clearance.min()))

    def probe_clearance(self) -> float:
        """Smallest clearance of the probe and its holder, m (``inf`` with no obstacle)."""
        if self.radii.shape[0] == 0:
            return float("inf")
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
    s = offsets(lz, obstacles.centers, state.radius)  # (J, k+1, 2)
    # Links [p_i, p_{i+1}] with l wrapped; closest point p̄ = p_i + t (p_{i+1} − p_i), t ∈ [0, 1].
    seg = lz[1:] - lz[:-1]
    seg[:, 0] = wrap(seg[:, 0], state.radius)
    length2 = np.maximum((seg * seg).sum(axis=-1), 1e-18)  # a zero-length link gives t = 0
    s_start = s[:, :-1]
    t = ((s_start * seg).sum(axis=-1) / length2).clip(0.0, 1.0)
    r = s_start - t[..., None] * seg
    result = Proximity(
        point_offsets=s,
        point_distance=np.sqrt((s * s).sum(axis=-1)),
        link_t=t,
        link_offsets=r,
        link_distance=np.sqrt((r * r).sum(axis=-1)),
        radii=obstacles.radii,
    )
    cache[obstacles] = result
    return result


def min_clearance(state: KinematicState, obstacles: ObstacleSet) -> float:
    """Smallest signed clearance (m) of any body point or link to ``obstacles``.

    Negative inside an obstacle; ``inf`` with no obstacles.
    """
    if not len(obstacles):
        return float("inf")
    return proximity(state, obstacles).min_clearance()
