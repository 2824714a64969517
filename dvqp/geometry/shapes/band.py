"""A band all the way round the pipe: a support or a clamp ring, ``z ∈ [z_min, z_max]``."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from dvqp import _validate
from dvqp.errors import ParameterError
from dvqp.geometry.shapes.shape import (
    HEIGHT_FIELD,
    Array,
    CompiledShape,
    Shape,
    ShapeKernels,
    checked_height,
)
from dvqp.workspace.wiring import overrides
from solvers.jit import njit

_FLAT = 1e-15
"""m: a link whose ends differ less in z is parallel to the band."""


@dataclass(frozen=True, eq=False)
class Band(Shape):
    """Every l, and z between ``z_min`` and ``z_max``.

    Its signed distance is ``max(z_min − z, z − z_max)``: exact, negative inside.

    Parameters
    ----------
    z_min, z_max
        m, ``z_min < z_max``.
    weight
        The objective weight ``w_j`` (>= 0).
    height
        m above the pipe surface, > 0 (default ``inf``: unbounded, a wall to the sky).
    """

    z_min: float
    z_max: float
    weight: float = 1.0
    height: float = math.inf
    kind: ClassVar[str] = "band"
    SCENE_FIELDS: ClassVar[dict[str, tuple[str, Any]]] = {
        "z": ("interval", None),
        "weight": ("weight", 1.0),
        **HEIGHT_FIELD,
    }

    def __post_init__(self) -> None:
        lo, hi = float(self.z_min), float(self.z_max)
        if not (np.isfinite(lo) and np.isfinite(hi)):
            raise ParameterError("z", "must be finite")
        if not lo < hi:
            raise ParameterError("z", f"needs z_min < z_max, got [{lo:g}, {hi:g}]")
        object.__setattr__(self, "z_min", lo)
        object.__setattr__(self, "z_max", hi)
        object.__setattr__(self, "weight", _validate.positive("weight", self.weight, strict=False))
        object.__setattr__(self, "height", checked_height(self.height))

    @classmethod
    def from_scene(cls, values: dict[str, Any], pipe_radius: float) -> Band:
        """From a scene file's ``[[obstacles]]`` table (keys :attr:`SCENE_FIELDS`)."""
        return cls(values["z"][0], values["z"][1], values["weight"], values["height"])

    @property
    def size(self) -> float:
        """Half the width, m."""
        return 0.5 * (self.z_max - self.z_min)

    @property
    def z_range(self) -> tuple[float, float]:
        """``(z_min, z_max)``, m."""
        return self.z_min, self.z_max

    def compiled(self) -> CompiledShape | None:
        """``[z_min, z_max, 0, 0]``, measured by :func:`band_point` and :func:`band_segment`
        (its box unbounded in l)."""
        if overrides(self, Band, "point_distance", "segment_distance"):
            return None
        low, high = float(self.z_min), float(self.z_max)
        box = (-math.inf, math.inf, low, high)
        return CompiledShape(KERNELS, (low, high, 0.0, 0.0), box, convex=True)

    def outline(self) -> Array:
        """``[[nan, z_min], [nan, z_max]]``: a band has edges, not a closed outline."""
        return np.array([[np.nan, self.z_min], [np.nan, self.z_max]])


@njit
def band_point(z_min: float, z_max: float, z: float) -> tuple[float, float]:
    """``max(z_min − z, z − z_max)`` (m) and ``∂d/∂z`` (∓1)."""
    below, above = z_min - z, z - z_max
    return max(below, above), -1.0 if below >= above else 1.0


@njit
def band_segment(z_min: float, z_max: float, za: float, zb: float) -> tuple[float, float, float]:
    """``(d, t, ∂d/∂z)`` of a segment from z ``za`` to ``zb``. The distance is convex and
    piecewise linear along it: its minimum is at an end or where the segment crosses the band's
    middle line (there it is ``−width/2`` and has no gradient: 0)."""
    dz = zb - za
    crossing = (0.5 * (z_min + z_max) - za) / dz if abs(dz) > _FLAT else 0.0
    crossing = min(max(crossing, 0.0), 1.0)
    best_k, best_t = 0, 0.0
    best = max(z_min - za, za - z_max)
    for k in range(1, 3):
        t = 1.0 if k == 1 else crossing
        z = za + t * dz
        value = max(z_min - z, z - z_max)
        if value < best:
            best, best_k, best_t = value, k, t
    d, nz = band_point(z_min, z_max, za + best_t * dz)
    if best_k == 2 and 0.0 < best_t < 1.0:
        nz = 0.0
    return d, best_t, nz


@njit
def measure_point(shapes, j, pl, pz):  # type: ignore[no-untyped-def]
    """:func:`band_point` of band j of ``shapes`` (``data[j] = [z_min, z_max, 0, 0]``)."""
    d, nz = band_point(shapes.data[j, 0], shapes.data[j, 1], pz)
    return d, 0.0, nz


@njit
def measure_segment(shapes, j, al, az, bl, bz, a_end, b_end):  # type: ignore[no-untyped-def]
    """:func:`band_segment` of band j of ``shapes`` (its ends' distances unused)."""
    d, t, nz = band_segment(shapes.data[j, 0], shapes.data[j, 1], az, bz)
    return d, t, 0.0, nz


KERNELS = ShapeKernels(measure_point, measure_segment)
"""How the compiled measurement measures a band."""
