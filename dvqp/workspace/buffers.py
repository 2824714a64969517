"""The arrays one configuration fills: its kinematics, its proximity to the obstacles, the pairs
of the arm's own links.

Each is allocated once per run and overwritten in place per state by compiled kernels. All
arrays are float64 (int64 and bool where said), C-contiguous and writable, so that a dataclass
of them packs into one numba struct (:func:`dvqp.workspace.struct.as_struct`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]


@dataclass(frozen=True)
class StateBuffers:
    """One configuration's kinematics (read them through :class:`dvqp.KinematicState`).

    Attributes
    ----------
    q : (n,)
        rad.
    origins, axes : (m, 3)
        Frame origins (m) and unit z axes of the guarded frames, base frame: the k body points,
        the tool, then the rail point if the arm has one (``m = k + 1`` or ``k + 2``).
    frame_jacobians : (m, 6, n)
        ``[J_v; J_ω]`` in the base orientation (Pinocchio's LOCAL_WORLD_ALIGNED).
    guarded : (m, 3)
        DV ``[l, z, h]`` (m) of the body points, the probe (the tool point), the rail point.
    guarded_jacobians : (m, 3, n)
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
    def allocate(cls, n: int, k: int, rail: bool = False) -> StateBuffers:
        """Zeroed buffers for n joints, k body points and the rail point if ``rail``."""
        m = k + 1 + rail
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


def link_ends(k: int, rail: bool = False) -> NDArray[np.int64]:
    """The guarded links as guarded-point indices ``(L, 2)``: body link i (``i < k − 1``) and the
    probe holder (``i = k − 1``) join points i and i+1; the carriage link (``i = k``, with a
    rail point) joins the rail point (``k + 1``) to body point 1 (0)."""
    ends = [(i, i + 1) for i in range(k)] + ([(k + 1, 0)] if rail else [])
    return np.array(ends, dtype=np.int64).reshape(-1, 2)


@dataclass(frozen=True)
class ProximityBuffers:
    """Signed distances of the m guarded points and the L guarded links to J obstacles.

    Point i < k is body point i+1, i = k the probe, i = k+1 the rail point or the base (if
    any); the links are :func:`link_ends`'s (``ends``): the body links, the probe holder, the
    carriage (or base) link. An obstacle is a solid: its footprint in the (l, z) plane extruded
    from the pipe surface up to its height (``dvqp.geometry.solid``; unbounded: a wall), so a
    distance's gradient is taken with respect to the DV ``[l, z, h]``.

    Attributes
    ----------
    ends : (L, 2) int64
        The points each link joins (constant).
    point_distance, point_penalty : (J, m)
        Signed distance ``d`` to the solid (m, negative inside) and the objective's penalty
        ``e`` (m²).
    point_normal, point_penalty_gradient : (J, m, 3)
        ``∇d`` and ``∇e`` with respect to the point's ``[l, z, h]``.
    link_distance, link_t : (J, L)
        The footprint's signed distance (m) at each straight DV segment's closest point
        ``p_a + t (p_b − p_a)`` in the (l, z) plane, and its ``t``.
    link_normal : (J, L, 2)
        ``∇d`` there, with respect to ``[l, z]``.
    straight_distance : (J, L)
        Of an obstacle with a height only: the straight DV segment's (its height linear
        between its ends) signed distance to the solid, m.
    straight_normal : (J, L, 3)
        ``∇d`` there with respect to ``[l, z, h]``.
    straight_at : (J, L, 2)
        The segment parameters its footprint part and its height part hold at.
    link_penalty : (J, L)
        The objective's penalty ``e`` of each straight DV segment (m²): of ``link_distance``,
        or of ``straight_distance`` for an obstacle with a height.
    link_penalty_gradient : (J, L, 3)
        ``∇e`` with respect to ``[l, z, h]``.
    link_penalty_at : (J, L, 2)
        The segment parameters its ``[l, z]`` part and its ``h`` part hold at.
    real_distance, real_at : (J, L)
        The clearance (m) of each link's real DV image (the straight 3-D link mapped to the
        DV; ``dvqp.geometry.real_links``) to the solid, and the link parameter of its closest
        point in the (l, z) plane.
    real_normal : (J, L, 3)
        ``∇d`` there, with respect to the point's ``[l, z, h]``.
    real_low : (J, L)
        The link parameter of the lowest point of the piece that has it (where the height
        part of ``real_normal`` holds).
    real_footprint : (J, L)
        ``∂d/∂d₂``: how much of ``real_normal``'s (l, z) part the footprint's distance ``d₂``
        carries (1 for an unbounded obstacle).
    real_upper : (J, L)
        An upper bound of that clearance (m) where the rows were measured exactly, for an
        obstacle with a height (its row one piece, or the piece that has it).
    real_t0, real_t1 : (J, L)
        The piece ``[t0, t1]`` of the link that has it.
    bends : (L,)
        How far each link's real DV image strays from its straight DV segment, m.
    skipped : (J,) bool
        The broad phase left obstacle j out (``dvqp.geometry.measure``): ``bound[j]`` is a
        lower bound of the clearance of every point and link to it (its real links': that
        less each link's bend), and none of its rows is written (they hold an earlier step's
        values; ``bound`` and ``bends`` are its rows).
    bound : (J,)
        That lower bound, m, where ``skipped`` (else not written).
    """

    ends: NDArray[np.int64]
    point_distance: Array
    point_normal: Array
    point_penalty: Array
    point_penalty_gradient: Array
    link_distance: Array
    link_normal: Array
    link_t: Array
    straight_distance: Array
    straight_normal: Array
    straight_at: Array
    link_penalty: Array
    link_penalty_gradient: Array
    link_penalty_at: Array
    real_distance: Array
    real_normal: Array
    real_at: Array
    real_low: Array
    real_footprint: Array
    real_upper: Array
    real_t0: Array
    real_t1: Array
    bends: Array
    skipped: NDArray[np.bool_]
    bound: Array

    @classmethod
    def allocate(cls, count: int, k: int, rail: bool = False) -> ProximityBuffers:
        """Zeroed buffers for ``count`` obstacles, k body points and the rail point (or the
        base) if ``rail``."""
        return cls.sized(count, k + 1 + rail, link_ends(k, rail))

    @classmethod
    def sized(cls, count: int, points: int, ends: NDArray[np.int64]) -> ProximityBuffers:
        """Zeroed buffers for ``count`` obstacles, ``points`` points and the links ``ends``."""
        p, s = (count, points), (count, ends.shape[0])
        return cls(
            ends=np.ascontiguousarray(ends, dtype=np.int64),
            point_distance=np.zeros(p),
            point_normal=np.zeros((*p, 3)),
            point_penalty=np.zeros(p),
            point_penalty_gradient=np.zeros((*p, 3)),
            link_distance=np.zeros(s),
            link_normal=np.zeros((*s, 2)),
            link_t=np.zeros(s),
            straight_distance=np.zeros(s),
            straight_normal=np.zeros((*s, 3)),
            straight_at=np.zeros((*s, 2)),
            link_penalty=np.zeros(s),
            link_penalty_gradient=np.zeros((*s, 3)),
            link_penalty_at=np.zeros((*s, 2)),
            real_distance=np.zeros(s),
            real_normal=np.zeros((*s, 3)),
            real_at=np.zeros(s),
            real_low=np.zeros(s),
            real_footprint=np.ones(s),
            real_upper=np.zeros(s),
            real_t0=np.zeros(s),
            real_t1=np.ones(s),
            bends=np.zeros(ends.shape[0]),
            skipped=np.zeros(count, np.bool_),
            bound=np.zeros(count),
        )


@dataclass(frozen=True)
class PairBuffers:
    """The pairs ``(i, j)``, ``i < j``, of guarded links that share no point, and their closest
    points.

    Attributes
    ----------
    ends : (L, 2) int64
        The points each link joins (:func:`link_ends`).
    i, j : (P,) int64
        Link indices (constant for a run).
    distance, s, t : (P,)
        ``‖c_i − c_j‖`` (m) and the closest points' parameters on links i and j.
    normal : (P, 3)
        Unit ``c_i − c_j``.
    """

    ends: NDArray[np.int64]
    i: NDArray[np.int64]
    j: NDArray[np.int64]
    distance: Array
    normal: Array
    s: Array
    t: Array

    @classmethod
    def allocate(cls, k: int, rail: bool = False) -> PairBuffers:
        """The pairs among the guarded links of k body points (and the rail point if
        ``rail``), geometry zeroed."""
        ends = link_ends(k, rail)
        pairs = [
            (a, b)
            for a in range(len(ends))
            for b in range(a + 1, len(ends))
            if not set(ends[a]) & set(ends[b])
        ]
        i, j = np.array(pairs, dtype=np.int64).reshape(-1, 2).T.copy()
        p = i.shape[0]
        return cls(ends, i, j, np.zeros(p), np.zeros((p, 3)), np.zeros(p), np.zeros(p))
