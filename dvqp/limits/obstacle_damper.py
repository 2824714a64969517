"""Velocity dampers that keep every guarded part out of the obstacle circles.

The guarded parts are the body points and the probe (the tool point), the body links and the
probe holder (last body point to the tool). For a pair (part, obstacle j) with signed
clearance ``d`` (m; a circle: ``‖S_j − p‖ − R_j``) below the influence distance ``d_i``, one
damper row (see :mod:`dvqp.limits.damper`) keeps ``d ≥ d_safe``. A link row is added only where its
closest point is interior; at an end the point's own row holds.
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from dvqp import _validate
from dvqp.compiled.plan import Kernel, ProximityBuffers, StepPlan
from dvqp.errors import ParameterError
from dvqp.geometry.obstacle import ObstacleSet
from dvqp.geometry.proximity import link_label, point_label, proximity
from dvqp.kinematics.state import KinematicState
from dvqp.limits.damper import DEFAULT_DECELERATION, Distances, VelocityDamper
from dvqp.limits.damper_kernels import clearance_values, obstacle_rows


class ObstacleDamper(VelocityDamper):
    """Keeps every guarded point and link at least ``margin`` from every obstacle.

    Parameters
    ----------
    obstacles
        Circles in (l, z); share the objective's :class:`ObstacleSet` so the per-state
        geometry is computed once.
    margin
        ``d_safe``, m, >= 0.
    influence
        ``d_i``, m, > margin: pairs farther than this add no row.
    gain
        ``γ`` in (0, 1].
    """

    name = "obstacles"
    quantity = "clearance"
    SCENE_KEYS: ClassVar[dict[str, str]] = {
        "damper_deceleration": "deceleration",
        "margin": "margin",
        "influence": "influence",
        "damper_gain": "gain",
    }
    """Keys of the scene file's ``[constraints]`` table -> constructor arguments."""

    def __init__(
        self, obstacles: ObstacleSet, margin: float = 0.01, influence: float = 0.06,
        gain: float = 0.5, deceleration: float = DEFAULT_DECELERATION,
    ) -> None:  # fmt: skip
        super().__init__(gain, deceleration)
        self.obstacles = ObstacleSet.of(obstacles)
        self.margin = _validate.positive("margin", margin, strict=False)
        if not float(influence) > self.margin or not np.isfinite(influence):
            raise ParameterError("influence", "must be finite and > margin")
        self.influence = float(influence)

    def distances(self, state: KinematicState) -> Distances:
        """Clearances (m) of the points and links within the influence distance."""
        if not len(self.obstacles):
            return Distances(np.zeros(0), np.zeros((0, state.n)), self.margin)
        near = proximity(state, self.obstacles)
        jac = state.guarded_jacobians[:, :2, :]  # (k+1, 2, n)
        points, links = near.points, near.links
        # Points: ∇d = n · ∂p/∂Q, n the outward normal (a circle: −(S − p)/‖S − p‖)
        usable = (points.normal != 0.0).any(axis=-1)  # no normal at a circle's centre
        pj, pi = np.nonzero((points.distance < self.influence) & usable)
        away = -points.normal[pj, pi]  # (p, 2)
        point_rows = (away[:, :, None] * jac[pi]).sum(axis=1)
        # Links: ∇d = n · ((1 − t) ∂p_i + t ∂p_{i+1}) at interior closest points
        t = links.t
        usable = (links.normal != 0.0).any(axis=-1) & (t > 0.0) & (t < 1.0)
        lj, li = np.nonzero((links.distance < self.influence) & usable)
        away = -links.normal[lj, li]
        tt = t[lj, li, None, None]
        link_rows = (away[:, :, None] * ((1.0 - tt) * jac[li] + tt * jac[li + 1])).sum(axis=1)
        k = state.k

        def describe() -> tuple[str, ...]:
            points = [f"{point_label(i, k)}/obstacle{j + 1}" for j, i in zip(pj, pi, strict=True)]
            links = [f"{link_label(i, k)}/obstacle{j + 1}" for j, i in zip(lj, li, strict=True)]
            return (*points, *links)

        value = np.concatenate([points.distance[pj, pi], links.distance[lj, li]])
        return Distances(value, -np.concatenate([point_rows, link_rows]), self.margin, describe)

    def all_distances(self, state: KinematicState) -> Distances:
        """Clearance (m) of every guarded point, then every guarded link, to every obstacle."""
        if not len(self.obstacles):
            return Distances(np.zeros(0), None, self.margin)
        near = proximity(state, self.obstacles)
        points, links = near.point_clearance, near.link_clearance  # (J, k+1), (J, k)
        k, count = state.k, len(self.obstacles)

        def describe() -> tuple[str, ...]:
            obstacles = range(count)
            return (
                *(f"{point_label(i, k)}/obstacle{j + 1}" for j in obstacles for i in range(k + 1)),
                *(f"{link_label(i, k)}/obstacle{j + 1}" for j in obstacles for i in range(k)),
            )

        values = np.concatenate([points.ravel(), links.ravel()])
        return Distances(values, None, self.margin, describe)

    def kernel(self, plan: StepPlan) -> Kernel | None:
        """``J (2k + 1)`` fixed rows: every (point, obstacle) pair then every (link, obstacle)
        pair, obstacle-major, from the plan's proximity buffers of :attr:`obstacles` (its
        shapes' kernels, in ``plan.geometry``, run before it); None with no obstacle.

        Raises NotImplementedError when a shape has no compiled kernel."""
        if not len(self.obstacles):
            return None
        near = _buffers(plan, self.obstacles)
        G, h = plan.constraint_rows(len(self.obstacles) * (2 * plan.k + 1))
        args = (near.point_distance, near.point_normal, near.link_distance, near.link_normal,
                near.link_t, plan.state.guarded_jacobians, self.influence,
                self.params(self.margin), plan.dt, G, h)  # fmt: skip
        return Kernel(obstacle_rows, args)

    def verifier(self, plan: StepPlan) -> Kernel | None:
        """Every point's then every link's clearance, m, obstacle-major (as
        :meth:`all_distances`), safe value ``margin``; None with no obstacle.

        Raises NotImplementedError when a shape has no compiled kernel."""
        if not len(self.obstacles):
            return None
        near = _buffers(plan, self.obstacles)
        count = len(self.obstacles) * (2 * plan.k + 1)
        slot = plan.verified(self, count, self.margin, self.tolerance)
        return Kernel(clearance_values, (near.point_distance, near.link_distance, slot))


def _buffers(plan: StepPlan, obstacles: ObstacleSet) -> ProximityBuffers:
    """The plan's proximity buffers of ``obstacles``; NotImplementedError if not compiled."""
    buffers = plan.proximity(obstacles)
    if buffers is None:
        raise NotImplementedError("an obstacle shape has no compiled proximity kernel")
    return buffers
