"""Self-collision: non-adjacent links of the snake body kept apart, in 3-D.

The guarded links are the segments between consecutive guarded points in the base frame: the
k − 1 body links and the probe holder (last body point to the tool). Every pair of
non-adjacent links ``(i, j)``, ``j ≥ i + 2``, keeps the distance between its segments
``d = ‖c_i − c_j‖`` at least ``margin`` (``c_i = a_i + s (b_i − a_i)``, ``c_j`` likewise, the
closest points; exact). With ``n = (c_i − c_j)/d`` and the frames' linear Jacobians ``J``::

    ∂d/∂Q = nᵀ ((1 − s) J_{a_i} + s J_{b_i} − (1 − t) J_{a_j} − t J_{b_j})

(the envelope theorem: moving the closest points along their segments does not change d to
first order). One damper row per pair closer than ``margin + influence``.

The compiled step computes the pairs' geometry once per state into the plan's pair buffers
(:func:`pairs_kernel`, with the same in-place routine the reference path uses); the rows
kernel (:meth:`SelfCollision.kernel`) reads them.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import ClassVar

import numpy as np
from numba import njit
from numpy.typing import NDArray

from dvqp import _validate
from dvqp.compiled.plan import Kernel, SelfPairBuffers, StepPlan
from dvqp.errors import ParameterError
from dvqp.geometry.proximity import link_label
from dvqp.kinematics.state import KinematicState
from dvqp.limits.damper import DEFAULT_DECELERATION, Distances, VelocityDamper
from dvqp.limits.damper_kernels import copy_values
from dvqp.limits.self_collision_kernels import pair_distances_into, self_rows

Array = NDArray[np.float64]


@functools.cache
def link_pairs(k: int) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Indices ``(i, j)`` of the non-adjacent pairs among the k guarded links (``j ≥ i + 2``)."""
    i, j = np.triu_indices(k, 2)
    return _validate.readonly(i.astype(np.int64)), _validate.readonly(j.astype(np.int64))


@njit(cache=True)
def pair_distances(o: Array, pi: NDArray[np.int64], pj: NDArray[np.int64]):  # type: ignore[no-untyped-def]
    """Distance, unit normal ``c_i − c_j``, ``s`` and ``t`` of the link pairs ``(pi, pj)``
    of the chain of points ``o``: segment ``o[pi] → o[pi+1]`` against ``o[pj] → o[pj+1]``.

    Ericson's clamped closest points (*Real-Time Collision Detection*, 5.1.9), exact for
    parallel and degenerate segments too; compiled (:func:`pair_distances_into`, which the
    compiled step calls in place)."""
    p = pi.shape[0]
    dist, normal, ss, tt = np.empty(p), np.empty((p, 3)), np.empty(p), np.empty(p)
    pair_distances_into(o, pi, pj, dist, normal, ss, tt)
    return dist, normal, ss, tt


def pairs_kernel(plan: StepPlan) -> tuple[SelfPairBuffers, Kernel]:
    """The pair buffers of ``plan``'s k guarded links and the kernel that fills them in place
    from ``plan.state.origins`` (once per state; see :meth:`StepPlan.self_pairs`)."""
    i, j = link_pairs(plan.k)
    p = i.shape[0]
    pairs = SelfPairBuffers(i, j, np.zeros(p), np.zeros((p, 3)), np.zeros(p), np.zeros(p))
    args = (plan.state.origins, i, j, pairs.distance, pairs.normal, pairs.s, pairs.t)
    return pairs, Kernel(pair_distances_into, args)


_CACHE_KEY = "self-collision pairs"


class SelfCollision(VelocityDamper):
    """Keeps every pair of non-adjacent guarded links at least ``margin`` apart (3-D).

    Parameters
    ----------
    margin
        Smallest distance between the axes of two non-adjacent links, m, >= 0 (the links'
        thickness plus a clearance).
    influence
        m, > 0: pairs farther than ``margin + influence`` add no row.
    gain
        ``γ`` in (0, 1].
    """

    name = "self"
    quantity = "self distance"
    SCENE_KEYS: ClassVar[dict[str, str]] = {
        "damper_deceleration": "deceleration",
        "self_margin": "margin",
        "damper_gain": "gain",
    }
    """Keys of the scene file's ``[constraints]`` table -> constructor arguments."""

    def __init__(
        self, margin: float = 0.02, influence: float = 0.05, gain: float = 0.5,
        deceleration: float = DEFAULT_DECELERATION,
    ) -> None:  # fmt: skip
        super().__init__(gain, deceleration)
        self.margin = _validate.positive("margin", margin, strict=False)
        self.influence = _validate.positive("influence", influence)
        if not np.isfinite(self.margin):
            raise ParameterError("margin", "must be finite")

    @staticmethod
    def _geometry(state: KinematicState) -> tuple[Array, Array, Array, Array, Array]:
        """Per pair: distance, unit normal, s, t, and the pair indices (once per state)."""
        found = state.cache.get(_CACHE_KEY)
        if found is not None:
            return found  # type: ignore[no-any-return]
        o = np.ascontiguousarray(state.origins)  # (k+1, 3): the body points, then the tool
        i, j = link_pairs(state.k)
        dist, normal, s, t = pair_distances(o, i, j)
        found = (dist, normal, s, t, np.stack([i, j]))
        state.cache[_CACHE_KEY] = found
        return found

    def distances(self, state: KinematicState) -> Distances:
        """Distances (m) of the pairs within ``margin + influence`` and their gradients."""
        dist, normal, s, t, (i, j) = self._geometry(state)
        near = np.flatnonzero(dist < self.margin + self.influence)
        jv = state.frame_jacobians[:, :3, :]  # (k+1, 3, n)
        sn, tn = s[near, None, None], t[near, None, None]
        ii, jj = i[near], j[near]
        moving = (1 - sn) * jv[ii] + sn * jv[ii + 1] - (1 - tn) * jv[jj] - tn * jv[jj + 1]
        gradient = (normal[near, :, None] * moving).sum(axis=1)
        return Distances(dist[near], gradient, self.margin, _labels(ii, jj, state.k))

    def all_distances(self, state: KinematicState) -> Distances:
        """Every non-adjacent pair's distance, m (no gradients), for verification."""
        dist, _, _, _, (i, j) = self._geometry(state)
        return Distances(dist, None, self.margin, _labels(i, j, state.k))

    def kernel(self, plan: StepPlan) -> Kernel | None:
        """One row per non-adjacent pair (``link_pairs(k)`` order), from the plan's pair
        buffers (:meth:`StepPlan.self_pairs`, run before it); None with no pair."""
        pairs = plan.self_pairs()
        if pairs.i.shape[0] == 0:
            return None
        G, h = plan.constraint_rows(pairs.i.shape[0])
        reach = self.margin + self.influence
        return Kernel(self_rows, (pairs.i, pairs.j, pairs.distance, pairs.normal, pairs.s,
                                  pairs.t, plan.state.frame_jacobians, reach,
                                  self.params(self.margin), plan.dt, G, h))  # fmt: skip

    def verifier(self, plan: StepPlan) -> Kernel | None:
        """Every pair's distance, m (safe value ``margin``); None with no pair."""
        pairs = plan.self_pairs()
        count = pairs.i.shape[0]
        if count == 0:
            return None
        slot = plan.verified(self, count, self.margin, self.tolerance)
        return Kernel(copy_values, (pairs.distance, slot))


def _labels(i: NDArray[np.int64], j: NDArray[np.int64], k: int) -> Callable[[], tuple[str, ...]]:
    """The pairs' names, e.g. ``"link1/link3"``, ``"link2/holder"``, computed when asked."""
    return lambda: tuple(
        f"{link_label(a, k)}/{link_label(b, k)}" for a, b in zip(i, j, strict=True)
    )


def self_distance(state: KinematicState) -> tuple[float, str]:
    """The smallest distance (m) between non-adjacent guarded links, and the pair's name."""
    dist, _, _, _, (i, j) = SelfCollision._geometry(state)
    if dist.shape[0] == 0:
        return float("inf"), ""
    m = int(np.argmin(dist))
    return float(dist[m]), f"{link_label(int(i[m]), state.k)}/{link_label(int(j[m]), state.k)}"
