"""A circle in the (l, z) plane: the paper's obstacle envelope."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from dvqp import _validate
from dvqp.geometry.shapes.shape import (
    HEIGHT_FIELD,
    Array,
    CompiledShape,
    Shape,
    ShapeKernels,
    checked_height,
)
from dvqp.kinematics.developed_view import wrap_period
from dvqp.workspace.wiring import overrides
from solvers.jit import njit

_TINY = 1e-12
"""m: a point closer than this to the centre has no normal (0)."""
_MIN_LENGTH2 = 1e-18
"""m²: a shorter link is a point (t = 0)."""


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
    height
        m above the pipe surface, > 0 (default ``inf``: unbounded, a wall to the sky).
    """

    center: NDArray[np.float64]
    radius: float
    weight: float = 1.0
    height: float = math.inf
    kind: ClassVar[str] = "circle"
    SCENE_FIELDS: ClassVar[dict[str, tuple[str, Any]]] = {
        "center": ("point", None),
        "radius": ("length", None),
        "weight": ("weight", 1.0),
        **HEIGHT_FIELD,
    }

    def __post_init__(self) -> None:
        center = _validate.readonly(_validate.vector("center", self.center, 2))
        object.__setattr__(self, "center", center)
        object.__setattr__(self, "radius", _validate.positive("radius", self.radius))
        object.__setattr__(self, "weight", _validate.positive("weight", self.weight, strict=False))
        object.__setattr__(self, "height", checked_height(self.height))

    @classmethod
    def from_scene(cls, values: dict[str, Any], pipe_radius: float) -> Circle:
        """From a scene file's ``[[obstacles]]`` table (keys :attr:`SCENE_FIELDS`)."""
        return cls(values["center"], values["radius"], values["weight"], values["height"])

    @property
    def size(self) -> float:
        """The radius, m."""
        return self.radius

    @property
    def z_range(self) -> tuple[float, float]:
        """``z ± radius``, m."""
        return float(self.center[1] - self.radius), float(self.center[1] + self.radius)

    def compiled(self) -> CompiledShape | None:
        """``[l, z, r, 0]``, measured by :func:`circle_point` and :func:`circle_segment`."""
        if overrides(self, Circle, "point_distance", "segment_distance"):
            return None
        (l, z), r = self.center, self.radius
        data, box = (float(l), float(z), float(r), 0.0), (-r, r, z - r, z + r)
        return CompiledShape(KERNELS, data, box, convex=True)

    def outline(self) -> Array:
        """128 points on the circle, closed, m."""
        a = np.linspace(0.0, 2.0 * np.pi, 129)
        return self.center + self.radius * np.column_stack([np.cos(a), np.sin(a)])


@njit(inline="always")
def _from_offset(sl: float, sz: float, radius: float) -> tuple[float, float, float]:
    """``‖s‖ − R`` and the normal ``−s/‖s‖`` (0 at the centre) from the offset ``s = S − p``."""
    dist = math.sqrt(sl * sl + sz * sz)
    if dist > _TINY:
        return dist - radius, -(sl / dist), -(sz / dist)
    return dist - radius, 0.0, 0.0


@njit
def circle_point(cl, cz, radius, pl, pz, period):  # type: ignore[no-untyped-def]
    """``(d, ∂d/∂l, ∂d/∂z)`` of the point ``(pl, pz)`` to the circle at ``(cl, cz)``, m."""
    return _from_offset(wrap_period(cl - pl, period), cz - pz, radius)


@njit
def circle_segment(cl, cz, radius, al, az, bl, bz, period):  # type: ignore[no-untyped-def]
    """``(d, t, ∂d/∂l, ∂d/∂z)`` of a segment: its closest point to the centre is
    ``p̄ = a + t (b − a)``, ``t = clip((S − a)·(b − a)/‖b − a‖², 0, 1)`` (exact)."""
    gl, gz = wrap_period(bl - al, period), bz - az
    length2 = max(gl * gl + gz * gz, _MIN_LENGTH2)  # a zero-length link gives t = 0
    sl, sz = wrap_period(cl - al, period), cz - az
    t = min(max((sl * gl + sz * gz) / length2, 0.0), 1.0)
    d, nl, nz = _from_offset(sl - t * gl, sz - t * gz, radius)
    return d, t, nl, nz


@njit
def measure_point(shapes, j, pl, pz):  # type: ignore[no-untyped-def]
    """:func:`circle_point` of circle j of ``shapes`` (``data[j] = [l, z, r, 0]``)."""
    data = shapes.data
    return circle_point(data[j, 0], data[j, 1], data[j, 2], pl, pz, shapes.period)


@njit
def measure_segment(shapes, j, al, az, bl, bz, a_end, b_end):  # type: ignore[no-untyped-def]
    """:func:`circle_segment` of circle j of ``shapes`` (its ends' distances unused)."""
    data = shapes.data
    return circle_segment(data[j, 0], data[j, 1], data[j, 2], al, az, bl, bz, shapes.period)


@njit
def measure_rows(shapes, j, chain, near) -> None:  # type: ignore[no-untyped-def]
    """Every row of circle j, exact, into ``near`` (a packed
    :class:`~dvqp.workspace.ProximityBuffers`): the points ``chain`` (m) and the links
    ``near.ends``, its data read once. A circle's 13 rows took 0.11 µs so, 1.4–1.6 µs by a
    call a row (the packed struct read at each), timed in a loop over the states of a
    fifty-obstacles run."""
    cl, cz, r, period = shapes.data[j, 0], shapes.data[j, 1], shapes.data[j, 2], shapes.period
    distance, normal = near.point_distance, near.point_normal
    for i in range(chain.shape[0]):
        d, nl, nz = circle_point(cl, cz, r, chain[i, 0], chain[i, 1], period)
        distance[j, i], normal[j, i, 0], normal[j, i, 1] = d, nl, nz
    ends, distance, normal, at = near.ends, near.link_distance, near.link_normal, near.link_t
    for i in range(ends.shape[0]):
        a, b = ends[i, 0], ends[i, 1]
        d, t, nl, nz = circle_segment(
            cl, cz, r, chain[a, 0], chain[a, 1], chain[b, 0], chain[b, 1], period
        )
        distance[j, i], at[j, i], normal[j, i, 0], normal[j, i, 1] = d, t, nl, nz


KERNELS = ShapeKernels(measure_point, measure_segment, rows=measure_rows)
"""How the compiled measurement measures a circle."""
