"""Velocity dampers that keep every guarded part out of the obstacles.

For a pair (guarded point or link, obstacle j) with signed clearance ``d`` (m; a circle:
``‖S_j − p‖ − R_j``; to an obstacle with a height, the distance to its solid,
:mod:`dvqp.geometry.solid`) below the influence distance ``d_i``, one damper row (see
:mod:`dvqp.limits.damper`) keeps ``d ≥ d_safe``. A link row applies only where its closest
point is interior; at an end the point's own row holds.
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from dvqp import _validate
from dvqp.errors import ParameterError
from dvqp.geometry.obstacle import ObstacleSet
from dvqp.geometry.proximity import measure_state
from dvqp.geometry.real_links import real_link_gradient
from dvqp.kinematics.state import KinematicState
from dvqp.limits.damper import DEFAULT_DECELERATION, Distances, VelocityDamper, fresh_rows
from dvqp.limits.limit import SceneLimits
from dvqp.workspace import PartNames, as_struct
from dvqp.workspace.wiring import StepWiring, overrides
from solvers.jit import njit


class ObstacleDamper(VelocityDamper):
    """Keeps every guarded point and link at least ``margin`` from every obstacle (compiled:
    :func:`obstacle_distances`, ``J (m + L)`` rows: m guarded points, L guarded links).

    Parameters
    ----------
    obstacles
        Shapes in (l, z).
    margin
        ``d_safe``, m, >= 0.
    influence
        ``d_i``, m, > margin: pairs farther than this add no row.
    gain
        ``γ`` in (0, 1].
    deceleration
        ``a``, m/s².
    """

    name = "obstacles"
    quantity = "clearance"
    SCENE_KEYS: ClassVar[dict[str, str]] = {
        "damper_deceleration": "deceleration",
        "margin": "margin",
        "influence": "influence",
        "damper_gain": "gain",
    }

    def __init__(
        self,
        obstacles: ObstacleSet,
        margin: float = 0.01,
        influence: float = 0.06,
        gain: float = 0.5,
        deceleration: float = DEFAULT_DECELERATION,
    ) -> None:
        super().__init__(gain, deceleration)
        self.obstacles = ObstacleSet.of(obstacles)
        self.margin = _validate.positive("margin", margin, strict=False)
        if not float(influence) > self.margin or not np.isfinite(influence):
            raise ParameterError("influence", "must be finite and > margin")
        self.influence = float(influence)

    @classmethod
    def from_scene(cls, scene: SceneLimits) -> ObstacleDamper:
        """The scene's obstacles, with its ``[constraints]`` keys."""
        return cls(scene.obstacles, **cls.scene_arguments(scene))

    @property
    def safe(self) -> float:
        """``margin``, m."""
        return self.margin

    @property
    def reach(self) -> float:  # type: ignore[override]
        """``influence``, m."""
        return self.influence

    @property
    def measured(self) -> ObstacleSet:
        """Its obstacles."""
        return self.obstacles

    def distances(self, state: KinematicState) -> Distances:
        """The rows :func:`obstacle_distances` writes at ``state`` (every row measured
        exactly: a run's broad phase may give a far obstacle's rows its lower bound)."""
        k, rail, count = state.k, state.rail, len(self.obstacles)
        near = measure_state(state, self.obstacles)
        distance, gradient, usable = fresh_rows(count * (2 * k + 1 + 2 * rail), state.n)
        obstacle_distances(
            as_struct(near),
            state.guarded_jacobians,
            state.origins,
            state.frame_jacobians,
            state.radius,
            np.full(distance.shape[0], self.reach),
            np.arange(count, dtype=np.int64),
            0,
            distance,
            gradient,
            usable,
        )
        labels = self.labels(state.part_names)
        return Distances(distance, gradient, self.safe, lambda: labels, usable)

    def join(self, step: StepWiring) -> None:
        """Rows of every guarded point and link to each of its obstacles (``2k + 1`` a
        obstacle, ``+ 2`` with a rail point), measured by :func:`obstacle_distances`."""
        if overrides(self, ObstacleDamper, "distances", "kernel"):
            return super().join(step)
        k, rail = step.plan.k, step.plan.rail
        members = step.rows_of(self.obstacles)
        count = members.shape[0] * (2 * k + 1 + 2 * rail)
        if count == 0:
            return None
        start = step.damper(self, count, self.labels(step.plan.names))
        table = step.measures
        table["obstacle_start"].append(start)
        table["obstacle_members"].extend(members.tolist())
        table["obstacle_offsets"].append(len(table["obstacle_members"]))
        step.refine(members, self.safe, self.reach)
        return None

    def series(self, count: int, k: int, rail: bool) -> list[tuple[str, str, slice | list[int]]]:
        """One clearance curve per obstacle: its points' rows and its links' (obstacle-major,
        as :meth:`labels`)."""
        names, points, links = self.obstacles.labels, k + 1 + rail, k + rail
        at = len(names) * points
        return [
            (
                "clearance",
                name,
                [
                    *range(j * points, (j + 1) * points),
                    *range(at + j * links, at + (j + 1) * links),
                ],
            )
            for j, name in enumerate(names)
        ]

    def labels(self, names: PartNames) -> tuple[str, ...]:
        """``"point3/obstacles[0]"`` (or ``"point3/<name>"``), ...: every point then every
        link (by their ``names``: the rail point and carriage link too if the arm has a
        rail), obstacle-major."""
        obstacles = self.obstacles.labels
        return (
            *(f"{point}/{name}" for name in obstacles for point in names.points),
            *(f"{link}/{name}" for name in obstacles for link in names.links),
        )


@njit(separate=True)
def obstacle_distances(
    near,
    jacobians,
    origins,
    frame_jacobians,
    radius,
    reach,
    members,
    start,
    distance,
    gradient,
    usable,
) -> None:  # type: ignore[no-untyped-def]
    """Clearances of every (point, obstacle) pair then every (link, obstacle) pair of the
    obstacles ``members`` (rows of ``near``, a packed ProximityBuffers), obstacle-major, from
    row ``start``: ``d``, ``∂d/∂Q = n · ∂p/∂Q`` and whether the normal is defined. A link's
    is its real clearance (:func:`~dvqp.geometry.real_links.real_links`, its gradient an
    envelope), defined where its closest point is inside it (to an obstacle with a height:
    its footprint's closest point or its lowest point, for the part of the normal that is not
    0). ``jacobians`` (m, 3, n) are the guarded points' DV Jacobians, ``origins`` (m, 3)
    and ``frame_jacobians`` (m, 6, n) their 3-D ones, ``radius`` the pipe's (m); a link row's
    gradient is written only below its ``reach`` (m, per row), where the row applies (a point
    row's too)."""
    r, points, n, ends = start, near.point_distance.shape[1], gradient.shape[1], near.ends
    for j in members:
        if near.skipped[j]:  # far from the whole arm: its bound, no row applies
            for i in range(points):
                distance[r + i], usable[r + i] = near.bound[j], False
            r += points
            continue
        for i in range(points):
            normal = near.point_normal[j, i]
            nl, nz, nh = normal[0], normal[1], normal[2]
            distance[r], usable[r] = near.point_distance[j, i], nl != 0.0 or nz != 0.0 or nh != 0.0
            if usable[r] and distance[r] < reach[r]:
                jac = jacobians[i]
                for c in range(n):
                    gradient[r, c] = nl * jac[0, c] + nz * jac[1, c] + nh * jac[2, c]
            r += 1
    for j in members:
        if near.skipped[j]:  # the bound less each link's bend
            for i in range(ends.shape[0]):
                distance[r + i], usable[r + i] = near.bound[j] - near.bends[i], False
            r += ends.shape[0]
            continue
        for i in range(ends.shape[0]):
            nl, nz, t = near.real_normal[j, i, 0], near.real_normal[j, i, 1], near.real_at[j, i]
            nh, low = near.real_normal[j, i, 2], near.real_low[j, i]
            distance[r] = near.real_distance[j, i]
            usable[r] = ((nl != 0.0 or nz != 0.0) and 0.0 < t < 1.0) or (
                nh != 0.0 and 0.0 < low < 1.0
            )
            if usable[r] and distance[r] < reach[r]:
                real_link_gradient(near, origins, frame_jacobians, radius, j, i, gradient[r])
            r += 1
