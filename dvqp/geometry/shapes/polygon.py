"""A simple polygon in the (l, z) plane: a weld-on pad, a bracket, a rail."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from dvqp import _validate
from dvqp.compiled.plan import Kernel, ProximityBuffers, StepPlan
from dvqp.errors import ParameterError, ShapeError
from dvqp.geometry.shapes import polygon_geometry as geo
from dvqp.geometry.shapes import polygon_kernels as kernels
from dvqp.geometry.shapes.shape import Array, Shape, local, local_segments


@dataclass(frozen=True, eq=False)
class Polygon(Shape):
    """A simple polygon (its edges do not cross), vertices listed either way round.

    Parameters
    ----------
    vertices
        ``[[l, z], ...]``, m, shape (V, 2), V >= 3, l unwrapped (a polygon may straddle the
        seam ``l = ±πR``).
    weight
        The objective weight ``w_j`` (>= 0).
    """

    vertices: Array
    weight: float = 1.0
    kind: ClassVar[str] = "polygon"
    SCENE_FIELDS: ClassVar[dict[str, tuple[str, Any]]] = {
        "vertices": ("points", None),
        "weight": ("weight", 1.0),
    }
    """Scene keys -> (kind of value, default); kinds: point, length, interval, points, weight."""
    l_ref: float = field(init=False)
    local_vertices: Array = field(init=False, repr=False)
    _vl: Array = field(init=False, repr=False)
    _vz: Array = field(init=False, repr=False)

    def __post_init__(self) -> None:
        v = np.asarray(self.vertices, dtype=np.float64)
        if v.ndim != 2 or v.shape[1] != 2:
            raise ShapeError("vertices", (-1, 2), v.shape)
        if v.shape[0] > 3 and np.array_equal(v[0], v[-1]):  # written closed: drop the repeat
            v = v[:-1]
        _check_simple(v)
        object.__setattr__(self, "vertices", _validate.readonly(v))
        object.__setattr__(self, "weight", _validate.positive("weight", self.weight, strict=False))
        l_ref = float(v[:, 0].mean())
        object.__setattr__(self, "l_ref", l_ref)
        object.__setattr__(self, "local_vertices", _validate.readonly(v - [l_ref, 0.0]))
        object.__setattr__(self, "_vl", np.ascontiguousarray(self.local_vertices[:, 0]))
        object.__setattr__(self, "_vz", np.ascontiguousarray(self.local_vertices[:, 1]))

    @classmethod
    def from_scene(cls, values: dict[str, Any], pipe_radius: float) -> Polygon:
        """From a scene file's ``[[obstacles]]`` table (keys :attr:`SCENE_FIELDS`).

        Every vertex must lie within half the circumference of the vertices' mean l: a wider
        polygon would wrap onto itself around the pipe.
        """
        shape = cls(values["vertices"], values["weight"])
        half = np.pi * pipe_radius
        if np.abs(shape.local_vertices[:, 0]).max() >= half:
            raise ParameterError(
                "vertices", f"spans more than the pipe's circumference (2πR = {2 * half:.4g} m)"
            )
        return shape

    @property
    def size(self) -> float:
        """``sqrt(area / π)``, m: the radius of the circle of the same area."""
        return float(np.sqrt(abs(geo.signed_area(self.vertices)) / np.pi))

    @property
    def z_range(self) -> tuple[float, float]:
        """Lowest and highest vertex z, m."""
        return float(self.vertices[:, 1].min()), float(self.vertices[:, 1].max())

    def outline(self) -> Array:
        """The vertices, closed."""
        return np.vstack([self.vertices, self.vertices[:1]])

    def point_distance(self, lz: Array, period: float) -> tuple[Array, Array]:
        """Distance to the nearest edge, negative inside (even-odd rule)."""
        p = local(lz, self.l_ref, period)
        return kernels.points_signed_distance(p[:, 0], p[:, 1], self._vl, self._vz)

    def segment_distance(self, a: Array, b: Array, period: float) -> tuple[Array, Array, Array]:
        """Exact for a segment that stays outside; the deepest point, found by sampling and a
        golden-section search, for one that enters. There the normal is the one at the deepest
        point (one side of a kink where it lies on the medial axis)."""
        la, lb = local_segments(a, b, self.l_ref, period)
        return kernels.segments_signed_distance(
            la[:, 0], la[:, 1], lb[:, 0], lb[:, 1], self._vl, self._vz
        )

    @classmethod
    def kernel(
        cls, shapes: Sequence[Shape], indices: NDArray[np.int64], plan: StepPlan,
        buffers: ProximityBuffers,
    ) -> Kernel:  # fmt: skip
        """:func:`~dvqp.geometry.shapes.polygon_kernels.polygons`, vertices packed once."""
        polygons = [s for s in shapes if isinstance(s, Polygon)]
        sizes = [p.size for p in polygons]
        return kernels.polygon_kernel(polygons, sizes, indices, plan, buffers)


def _check_simple(v: Array) -> None:
    if v.shape[0] < 3:
        raise ParameterError("vertices", f"need at least 3 vertices, got {v.shape[0]}")
    if not np.isfinite(v).all():
        raise ParameterError("vertices", "must be finite")
    repeated = np.flatnonzero((v == np.roll(v, 1, axis=0)).all(axis=1))
    if repeated.size:
        raise ParameterError("vertices", f"vertex {int(repeated[0])} repeats the one before it")
    if geo.self_intersects(v):
        raise ParameterError("vertices", "the polygon's edges cross (it must be simple)")
    if abs(geo.signed_area(v)) < 1e-10:
        raise ParameterError("vertices", "the polygon has no area")
