"""A band all the way round the pipe: a support or a clamp ring, ``z ∈ [z_min, z_max]``."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from dvqp import _validate
from dvqp.compiled.plan import Kernel, ProximityBuffers, StepPlan
from dvqp.errors import ParameterError
from dvqp.geometry.shapes import band_kernels
from dvqp.geometry.shapes.shape import Array, Shape
from dvqp.geometry.shapes.shape_kernels import proximity_outputs


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
    """

    z_min: float
    z_max: float
    weight: float = 1.0
    kind: ClassVar[str] = "band"
    SCENE_FIELDS: ClassVar[dict[str, tuple[str, Any]]] = {
        "z": ("interval", None),
        "weight": ("weight", 1.0),
    }
    """Scene keys -> (kind of value, default); kinds: point, length, interval, points, weight."""

    def __post_init__(self) -> None:
        lo, hi = float(self.z_min), float(self.z_max)
        if not (np.isfinite(lo) and np.isfinite(hi)):
            raise ParameterError("z", "must be finite")
        if not lo < hi:
            raise ParameterError("z", f"needs z_min < z_max, got [{lo:g}, {hi:g}]")
        object.__setattr__(self, "z_min", lo)
        object.__setattr__(self, "z_max", hi)
        object.__setattr__(self, "weight", _validate.positive("weight", self.weight, strict=False))

    @classmethod
    def from_scene(cls, values: dict[str, Any], pipe_radius: float) -> Band:
        """From a scene file's ``[[obstacles]]`` table (keys :attr:`SCENE_FIELDS`)."""
        return cls(values["z"][0], values["z"][1], values["weight"])

    @property
    def size(self) -> float:
        """Half the width, m."""
        return 0.5 * (self.z_max - self.z_min)

    @property
    def z_range(self) -> tuple[float, float]:
        """``(z_min, z_max)``, m."""
        return self.z_min, self.z_max

    def outline(self) -> Array:
        """``[[nan, z_min], [nan, z_max]]``: a band has edges, not a closed outline."""
        return np.array([[np.nan, self.z_min], [np.nan, self.z_max]])

    def point_distance(self, lz: Array, period: float) -> tuple[Array, Array]:
        """``max(z_min − z, z − z_max)`` and ``(0, ∓1)``."""
        z = np.asarray(lz, dtype=np.float64)[:, 1]
        below, above = self.z_min - z, z - self.z_max
        d = np.maximum(below, above)
        normal = np.zeros((z.shape[0], 2))
        normal[:, 1] = np.where(below >= above, -1.0, 1.0)
        return d, normal

    def segment_distance(self, a: Array, b: Array, period: float) -> tuple[Array, Array, Array]:
        """The distance is convex and piecewise linear along a segment: its minimum is at an
        end or where the segment crosses the band's middle line (there it is ``−width/2`` and
        has no gradient: the normal returned is 0)."""
        za, zb = np.asarray(a)[:, 1], np.asarray(b)[:, 1]
        mid = 0.5 * (self.z_min + self.z_max)
        dz = zb - za
        crossing = np.where(np.abs(dz) > 1e-15, (mid - za) / np.where(dz == 0, 1.0, dz), 0.0)
        candidates = np.stack([np.zeros_like(za), np.ones_like(za), crossing.clip(0.0, 1.0)])
        z = za[None] + candidates * dz[None]  # (3, m)
        values = np.maximum(self.z_min - z, z - self.z_max)
        k = np.argmin(values, axis=0)
        cols = np.arange(za.shape[0])
        t = candidates[k, cols]
        zt = za + t * dz
        d, n = self.point_distance(np.column_stack([np.zeros_like(zt), zt]), period)
        # crossing the middle line the distance is −width/2 whatever the ends do: no gradient
        n[(k == 2) & (t > 0.0) & (t < 1.0)] = 0.0
        return d, t, n

    @classmethod
    def kernel(
        cls, shapes: Sequence[Shape], indices: NDArray[np.int64], plan: StepPlan,
        buffers: ProximityBuffers,
    ) -> Kernel:  # fmt: skip
        """:func:`~dvqp.geometry.shapes.band_kernels.bands`, the edges packed once."""
        bands = [s for s in shapes if isinstance(s, Band)]
        z_min = np.array([b.z_min for b in bands], dtype=np.float64)
        z_max = np.array([b.z_max for b in bands], dtype=np.float64)
        sizes = np.array([b.size for b in bands], dtype=np.float64)
        args = (plan.state.guarded, plan.period, z_min, z_max, sizes, indices)
        return Kernel(band_kernels.bands, (*args, *proximity_outputs(buffers)))
