"""Self-collision: non-adjacent links of the snake body kept apart, in 3-D.

The guarded links (the body links, the probe holder and the carriage link) are segments in the
base frame. Every pair of links ``(i, j)`` that share no point keeps the distance between its
segments ``d = ‖c_i − c_j‖`` at least ``margin`` (``c_i = a_i + s (b_i − a_i)``, ``c_j``
likewise, the closest points; exact). With ``n = (c_i − c_j)/d`` and the frames' linear
Jacobians ``J``::

    ∂d/∂Q = nᵀ ((1 − s) J_{a_i} + s J_{b_i} − (1 − t) J_{a_j} − t J_{b_j})

(the envelope theorem: moving the closest points along their segments does not change d to
first order). One damper row per pair, applying while closer than ``margin + influence``.
"""

from __future__ import annotations

import math
from typing import ClassVar

import numpy as np

from dvqp import _validate
from dvqp.kinematics.state import KinematicState
from dvqp.limits.damper import DEFAULT_DECELERATION, Distances, VelocityDamper, fresh_rows
from dvqp.workspace import PairBuffers, PartNames, as_struct
from dvqp.workspace.wiring import StepWiring, overrides
from solvers.jit import njit


class SelfCollision(VelocityDamper):
    """Keeps every pair of non-adjacent guarded links at least ``margin`` apart (3-D;
    compiled: :func:`pair_distances`, :func:`self_distances`).

    Parameters
    ----------
    margin
        Smallest distance between the axes of two non-adjacent links, m, >= 0 (the links'
        thickness plus a clearance).
    influence
        m, > 0: pairs farther than ``margin + influence`` add no row.
    gain
        ``γ`` in (0, 1].
    deceleration
        ``a``, m/s².
    """

    name = "self"
    quantity = "self distance"
    IN_EVERY_SCENE = True
    SCENE_KEYS: ClassVar[dict[str, str]] = {
        "damper_deceleration": "deceleration",
        "self_margin": "margin",
        "damper_gain": "gain",
    }

    def __init__(
        self,
        margin: float = 0.02,
        influence: float = 0.05,
        gain: float = 0.5,
        deceleration: float = DEFAULT_DECELERATION,
    ) -> None:
        super().__init__(gain, deceleration)
        self.margin = _validate.positive("margin", margin, strict=False)
        self.influence = _validate.positive("influence", influence)

    @property
    def safe(self) -> float:
        """``margin``, m."""
        return self.margin

    @property
    def reach(self) -> float:  # type: ignore[override]
        """``margin + influence``, m."""
        return self.margin + self.influence

    def series(self, count: int, k: int, rail: bool) -> list[tuple[str, str, slice | list[int]]]:
        """One curve: the least over the non-adjacent link pairs."""
        return [("self distance", "non-adjacent links", slice(0, count))]

    def distances(self, state: KinematicState) -> Distances:
        """The rows :func:`pair_distances` and :func:`self_distances` write at ``state``."""
        pairs = PairBuffers.allocate(state.k, state.rail)
        distance, gradient, usable = fresh_rows(pairs.i.shape[0], state.n)
        packed = as_struct(pairs)
        pair_distances(np.ascontiguousarray(state.origins), packed)
        self_distances(packed, state.frame_jacobians, 0, distance, gradient, usable)
        labels = self.labels(state.part_names)
        return Distances(distance, gradient, self.safe, lambda: labels, usable)

    def join(self, step: StepWiring) -> None:
        """A row per pair of non-adjacent guarded links, measured by :func:`self_distances`."""
        if overrides(self, SelfCollision, "distances", "kernel"):
            return super().join(step)
        plan = step.plan
        count = plan.pairs.i.shape[0]
        if count:
            step.measures["selves"].append(step.damper(self, count, self.labels(plan.names)))
        return None

    def labels(self, names: PartNames) -> tuple[str, ...]:
        """The pairs' names, e.g. ``"link1/link3"``, ``"link2/holder"``, ``"link2/carriage"``
        (the links' ``names``)."""
        pairs = PairBuffers.allocate(names.k, names.rail)
        return tuple(_pair(names, a, b) for a, b in zip(pairs.i, pairs.j, strict=True))


@njit(separate=True, python=True)  # Python calls it in every plan too
def pair_distances(o, pairs) -> None:  # type: ignore[no-untyped-def]
    """Distance, unit normal ``c_i − c_j``, ``s`` and ``t`` of the link pairs of the guarded
    points ``o`` (m, 3) into ``pairs`` (a packed PairBuffers): link i's segment
    ``o[ends[i, 0]] → o[ends[i, 1]]`` against link j's. Ericson's clamped closest points
    (*Real-Time Collision Detection*, 5.1.9), exact for parallel and degenerate segments too."""
    eps, ends = 1e-18, pairs.ends
    for m in range(pairs.i.shape[0]):
        i, j = pairs.i[m], pairs.j[m]
        a, b, c, d = o[ends[i, 0]], o[ends[i, 1]], o[ends[j, 0]], o[ends[j, 1]]
        d1x, d1y, d1z = b[0] - a[0], b[1] - a[1], b[2] - a[2]
        d2x, d2y, d2z = d[0] - c[0], d[1] - c[1], d[2] - c[2]
        rx, ry, rz = a[0] - c[0], a[1] - c[1], a[2] - c[2]
        aa = d1x * d1x + d1y * d1y + d1z * d1z
        e = d2x * d2x + d2y * d2y + d2z * d2z
        f = d2x * rx + d2y * ry + d2z * rz
        if aa <= eps and e <= eps:
            s, t = 0.0, 0.0
        elif aa <= eps:
            s, t = 0.0, min(max(f / e, 0.0), 1.0)
        else:
            cc = d1x * rx + d1y * ry + d1z * rz
            if e <= eps:
                s, t = min(max(-cc / aa, 0.0), 1.0), 0.0
            else:
                bb = d1x * d2x + d1y * d2y + d1z * d2z
                denom = aa * e - bb * bb
                s = min(max((bb * f - cc * e) / denom, 0.0), 1.0) if denom > eps * aa * e else 0.0
                t = (bb * s + f) / e
                if t < 0.0:
                    s, t = min(max(-cc / aa, 0.0), 1.0), 0.0
                elif t > 1.0:
                    s, t = min(max((bb - cc) / aa, 0.0), 1.0), 1.0
        x = (a[0] + s * d1x) - (c[0] + t * d2x)
        y = (a[1] + s * d1y) - (c[1] + t * d2y)
        z = (a[2] + s * d1z) - (c[2] + t * d2z)
        dist = math.sqrt(x * x + y * y + z * z)
        scale = max(dist, 1e-15)
        pairs.distance[m], pairs.s[m], pairs.t[m] = dist, s, t
        pairs.normal[m, 0], pairs.normal[m, 1], pairs.normal[m, 2] = x / scale, y / scale, z / scale


@njit(separate=True)
def self_distances(pairs, jac, start, distance, gradient, usable) -> None:  # type: ignore[no-untyped-def]
    """Every pair's distance (m) and ``∂d/∂Q`` (see the module docstring) from row ``start``
    (``jac`` the guarded frames' (m, 6, n) Jacobians)."""
    e = pairs.ends
    for m in range(pairs.i.shape[0]):
        i, j, sm, tm, r = pairs.i[m], pairs.j[m], pairs.s[m], pairs.t[m], start + m
        a, b, f, g = e[i, 0], e[i, 1], e[j, 0], e[j, 1]
        distance[r], usable[r] = pairs.distance[m], True
        for c in range(gradient.shape[1]):
            grad = 0.0
            for x in range(3):
                moving = (1 - sm) * jac[a, x, c] + sm * jac[b, x, c]
                moving = moving - (1 - tm) * jac[f, x, c] - tm * jac[g, x, c]
                grad += pairs.normal[m, x] * moving
            gradient[r, c] = grad


def self_distance(state: KinematicState) -> tuple[float, str]:
    """The smallest distance (m) between non-adjacent guarded links of ``state``, and the
    pair's name (``inf`` and ``""`` without such pairs)."""
    pairs = PairBuffers.allocate(state.k, state.rail)
    if pairs.i.shape[0] == 0:
        return math.inf, ""
    pair_distances(np.array(state.origins), as_struct(pairs))
    m = int(np.argmin(pairs.distance))
    return float(pairs.distance[m]), _pair(state.part_names, pairs.i[m], pairs.j[m])


def _pair(names: PartNames, a: int, b: int) -> str:
    """``"<link a>/<link b>"``."""
    return f"{names.link(int(a))}/{names.link(int(b))}"
