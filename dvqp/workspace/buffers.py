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
    origins, axes : (k+1, 3)
        Frame origins (m) and unit z axes of the k body points then the tool, base frame.
    frame_jacobians : (k+1, 6, n)
        ``[J_v; J_ω]`` in the base orientation (Pinocchio's LOCAL_WORLD_ALIGNED).
    guarded : (k+1, 3)
        DV ``[l, z, h]`` (m) of the body points then the probe (the tool point).
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
        return cls(np.zeros(n), np.zeros((m, 3)), np.zeros((m, 3)), np.zeros((m, 6, n)),
                   np.zeros((m, 3)), np.zeros((m, 3, n)), np.zeros(4),
                   np.zeros((4, n)))  # fmt: skip


@dataclass(frozen=True)
class ProximityBuffers:
    """Signed distances of the k+1 guarded points and the k guarded links to J obstacles.

    Index i < k is body point i+1, i = k the probe; link i < k−1 is body link i+1, link k−1 the
    probe holder (last body point to the tool).

    Attributes
    ----------
    point_distance, point_penalty : (J, k+1)
        Signed distance ``d`` (m, negative inside) and the objective's penalty ``e`` (m²).
    point_normal, point_penalty_gradient : (J, k+1, 2)
        ``∇d`` and ``∇e`` with respect to the point's ``[l, z]``.
    link_distance, link_penalty, link_t : (J, k)
        The same at each link's closest point ``p_i + t (p_{i+1} − p_i)``, and its ``t``.
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
        return cls(np.zeros(p), np.zeros((*p, 2)), np.zeros(p), np.zeros((*p, 2)), np.zeros(s),
                   np.zeros((*s, 2)), np.zeros(s), np.zeros((*s, 2)), np.zeros(s))  # fmt: skip


@dataclass(frozen=True)
class PairBuffers:
    """The non-adjacent guarded link pairs ``(i, j)``, ``j ≥ i + 2``, and their closest points.

    Attributes
    ----------
    i, j : (P,) int64
        Link indices (constant for a run).
    distance, s, t : (P,)
        ``‖c_i − c_j‖`` (m) and the closest points' parameters on links i and j.
    normal : (P, 3)
        Unit ``c_i − c_j``.
    """

    i: NDArray[np.int64]
    j: NDArray[np.int64]
    distance: Array
    normal: Array
    s: Array
    t: Array

    @classmethod
    def allocate(cls, k: int) -> PairBuffers:
        """The pairs among the k guarded links, geometry zeroed."""
        i, j = np.triu_indices(k, 2)
        p = i.shape[0]
        return cls(i.astype(np.int64), j.astype(np.int64), np.zeros(p), np.zeros((p, 3)),
                   np.zeros(p), np.zeros(p))  # fmt: skip
