"""A circle in the (l, z) plane: the paper's obstacle envelope."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from dvqp import _validate
from dvqp.compiled.plan import Kernel, ProximityBuffers, StepPlan
from dvqp.geometry.shapes import circle_kernels
from dvqp.geometry.shapes.shape import Array, Shape, ShapeDistances, wrap_l
from dvqp.geometry.shapes.shape_kernels import proximity_outputs

_TINY = 1e-12


@dataclass(frozen=True, eq=False)
class Circle(Shape):
    """A circle in the (l, z) plane of the developed view.

    Parameters
    ----------
    center
        ``[l, z]`` of the centre, m, shape (2,).
    radius
        Radius, m, > 0.
    weight
        The objective weight ``w_j`` (>= 0).
    """

    center: NDArray[np.float64]
    radius: float
    weight: float = 1.0
    kind: ClassVar[str] = "circle"
    SCENE_FIELDS: ClassVar[dict[str, tuple[str, Any]]] = {
        "center": ("point", None),
        "radius": ("length", None),
        "weight": ("weight", 1.0),
    }
    """Scene keys -> (kind of value, default); kinds: point, length, interval, points, weight."""

    def __post_init__(self) -> None:
        center = _validate.readonly(_validate.vector("center", self.center, 2))
        object.__setattr__(self, "center", center)
        object.__setattr__(self, "radius", _validate.positive("radius", self.radius))
        object.__setattr__(self, "weight", _validate.positive("weight", self.weight, strict=False))

    @classmethod
    def from_scene(cls, values: dict[str, Any], pipe_radius: float) -> Circle:
        """From a scene file's ``[[obstacles]]`` table (keys :attr:`SCENE_FIELDS`)."""
        return cls(values["center"], values["radius"], values["weight"])

    @property
    def size(self) -> float:
        """The radius, m."""
        return self.radius

    @property
    def z_range(self) -> tuple[float, float]:
        """``z ± radius``, m."""
        return float(self.center[1] - self.radius), float(self.center[1] + self.radius)

    def outline(self) -> Array:
        """128 points on the circle, closed, m."""
        a = np.linspace(0.0, 2.0 * np.pi, 129)
        return self.center + self.radius * np.column_stack([np.cos(a), np.sin(a)])

    def point_distance(self, lz: Array, period: float) -> tuple[Array, Array]:
        """``‖S − p‖ − R`` and ``−(S − p)/‖S − p‖`` (0 at the centre)."""
        d = Circle.batch_points([self], lz, period)
        return d.distance[0], d.normal[0]

    def segment_distance(self, a: Array, b: Array, period: float) -> tuple[Array, Array, Array]:
        """Closest point of each segment to the centre, in closed form."""
        d = Circle.batch_segments([self], a, b, period)
        return d.distance[0], d.t[0], d.normal[0]

    @classmethod
    def batch_points(cls, shapes: Sequence[Shape], lz: Array, period: float) -> ShapeDistances:
        """All circles at once: offsets ``S_j − p_i`` (J, m, 2), penalty ``‖S − p‖² − R²``."""
        centers, radii = _pack(shapes)
        s = _offsets(lz, centers, period)
        dist = np.sqrt((s * s).sum(axis=-1))
        return _distances(s, dist, radii, np.zeros_like(dist))

    @classmethod
    def batch_segments(
        cls, shapes: Sequence[Shape], a: Array, b: Array, period: float
    ) -> ShapeDistances:
        """Closest point ``p̄ = a + t (b − a)``, ``t = clip((S − a)·(b − a)/‖b − a‖², 0, 1)``."""
        centers, radii = _pack(shapes)
        seg = np.asarray(b, dtype=np.float64) - np.asarray(a, dtype=np.float64)
        seg[:, 0] = wrap_l(seg[:, 0], period)
        length2 = np.maximum((seg * seg).sum(axis=-1), 1e-18)  # a zero-length link gives t = 0
        s_start = _offsets(a, centers, period)
        t = ((s_start * seg).sum(axis=-1) / length2).clip(0.0, 1.0)
        r = s_start - t[..., None] * seg
        return _distances(r, np.sqrt((r * r).sum(axis=-1)), radii, t)

    @classmethod
    def kernel(
        cls, shapes: Sequence[Shape], indices: NDArray[np.int64], plan: StepPlan,
        buffers: ProximityBuffers,
    ) -> Kernel:  # fmt: skip
        """:func:`~dvqp.geometry.shapes.circle_kernels.circles`, centres and radii packed once."""
        centers, radii = _pack(shapes)
        args = (plan.state.guarded, plan.period, centers, radii, indices)
        return Kernel(circle_kernels.circles, (*args, *proximity_outputs(buffers)))


def _pack(shapes: Sequence[Shape]) -> tuple[Array, Array]:
    circles = [s for s in shapes if isinstance(s, Circle)]
    return np.array([c.center for c in circles]), np.array([c.radius for c in circles])


def _offsets(lz: Array, centers: Array, period: float) -> Array:
    """``S_j − p_i`` with l wrapped: shape (J, m, 2), m."""
    d = centers[:, None, :] - np.asarray(lz, dtype=np.float64)[None]
    d[..., 0] = wrap_l(d[..., 0], period)
    return d


def _distances(s: Array, dist: Array, radii: Array, t: Array) -> ShapeDistances:
    """From offsets ``s`` = centre minus point and their norms."""
    safe = np.where(dist > _TINY, dist, 1.0)
    normal = np.where((dist > _TINY)[..., None], -(s / safe[..., None]), 0.0)
    return ShapeDistances(
        distance=dist - radii[:, None],
        normal=normal,
        penalty=dist**2 - radii[:, None] ** 2,
        penalty_gradient=-2.0 * s,
        t=t,
    )
