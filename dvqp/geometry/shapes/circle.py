"""A circle in the (l, z) plane: the paper's obstacle envelope."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from dvqp import _validate
from dvqp.geometry.shapes.shape import CIRCLE, Array, CompiledShape, Shape
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

    def compiled(self) -> CompiledShape | None:
        """``[l, z, r, 0]``, measured by :func:`circle_point` and :func:`circle_segment`."""
        if overrides(self, Circle, "point_distance", "segment_distance"):
            return None
        (l, z), r = self.center, self.radius
        return CompiledShape(CIRCLE, (float(l), float(z), float(r), 0.0), (-r, r, z - r, z + r))

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
