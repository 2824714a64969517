"""What every obstacle shape provides: signed distances of points and segments, with gradients.

A shape lives in the developed view's (l, z) plane (m). Its signed distance ``d`` is negative
inside. For a point ``p`` it gives ``d(p)`` and the normal ``∇_p d`` (a unit vector away from
the nearest outline point); for a segment ``[a, b]`` the smallest signed distance over the
segment, the parameter ``t`` of the point ``p̄ = a + t (b − a)`` that has it, and the normal
there, so that ``∂d/∂a = (1 − t) ∇d`` and ``∂d/∂b = t ∇d`` (the envelope theorem).

The objective's repulsion uses the penalty ``e = d (d + 2ρ)`` with ``ρ`` the shape's
:attr:`Shape.size`, negative exactly inside; for a circle of radius ``R`` this is the paper's
``‖S − p‖² − R²``. Differences in l are wrapped modulo ``2πR`` (``period``).

Shapes of one class are evaluated together (:meth:`Shape.batch_points`,
:meth:`Shape.batch_segments`); the default loops over them, a class may vectorise.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from dvqp.compiled.plan import Kernel, ProximityBuffers, StepPlan

Array = NDArray[np.float64]


@dataclass(frozen=True)
class ShapeDistances:
    """Signed distances of m points (or segments) to J shapes, and what the step needs of them.

    Attributes
    ----------
    distance : ndarray, shape (J, m)
        Signed distance, m (negative inside).
    normal : ndarray, shape (J, m, 2)
        ``∇d`` with respect to the point (for a segment: at its closest point).
    penalty : ndarray, shape (J, m)
        ``e`` of the objective, m² (negative inside).
    penalty_gradient : ndarray, shape (J, m, 2)
        ``∇e``, m.
    t : ndarray, shape (J, m)
        For segments: parameter in [0, 1] of the closest point (zeros for points).
    """

    distance: Array
    normal: Array
    penalty: Array
    penalty_gradient: Array
    t: Array

    @staticmethod
    def stack(parts: Sequence[ShapeDistances]) -> ShapeDistances:
        """Shapes of several batches, in order."""
        return ShapeDistances(*(np.concatenate([getattr(p, f) for p in parts]) for f in _FIELDS))


_FIELDS = ("distance", "normal", "penalty", "penalty_gradient", "t")


class Shape(ABC):
    """An obstacle in the developed view: a region of the (l, z) plane with a weight.

    Attributes
    ----------
    kind : str
        The scene file's ``shape`` value.
    SCENE_FIELDS : dict
        The keys of its scene table (see :meth:`from_scene`).
    weight : float
        The objective weight ``w_j`` (>= 0).
    """

    kind: ClassVar[str]
    SCENE_FIELDS: ClassVar[dict[str, tuple[str, Any]]]
    """The keys of its scene table: ``key -> (kind of value, default or None)``, the kinds
    being ``point`` ([l, z], m), ``length`` (m, > 0), ``interval`` ([lo, hi], m), ``points``
    ([[l, z], ...], m) and ``weight`` (>= 0)."""
    weight: float

    @classmethod
    @abstractmethod
    def from_scene(cls, values: dict[str, Any], pipe_radius: float) -> Shape:
        """The shape from its scene table's values (checked for type and bounds already)."""

    @property
    @abstractmethod
    def size(self) -> float:
        """``ρ`` of the penalty ``d (d + 2ρ)``, m: the shape's radius or half width."""

    @property
    @abstractmethod
    def z_range(self) -> tuple[float, float]:
        """Lowest and highest z of the shape, m (for plot limits)."""

    @abstractmethod
    def outline(self) -> Array:
        """The boundary as a closed polyline ``(P, 2)`` in (l, z), l unwrapped, m, for plots.

        A band has no bounded outline: it returns its two edges' z as a (2, 2) array
        ``[[nan, z_min], [nan, z_max]]``.
        """

    @abstractmethod
    def point_distance(self, lz: Array, period: float) -> tuple[Array, Array]:
        """Signed distance ``(m,)`` and normal ``(m, 2)`` of m points ``lz`` (m, 2)."""

    @abstractmethod
    def segment_distance(self, a: Array, b: Array, period: float) -> tuple[Array, Array, Array]:
        """Smallest signed distance ``(m,)``, its parameter ``t`` ``(m,)`` and the normal there
        ``(m, 2)``, of m segments from ``a`` to ``b`` (each (m, 2))."""

    def penalty(self, distance: Array, normal: Array) -> tuple[Array, Array]:
        """``e = d (d + 2ρ)`` and ``∇e = 2 (d + ρ) ∇d``."""
        rho = self.size
        return distance * (distance + 2.0 * rho), (2.0 * (distance + rho))[..., None] * normal

    @classmethod
    def kernel(
        cls, shapes: Sequence[Shape], indices: NDArray[np.int64], plan: StepPlan,
        buffers: ProximityBuffers,
    ) -> Kernel | None:  # fmt: skip
        """The compiled kernel that writes rows ``indices`` of ``buffers`` (this class's
        shapes against the guarded points and links of ``plan.state``), or None: a class
        without one makes the run take the reference (uncompiled) path."""
        return None

    @classmethod
    def batch_points(cls, shapes: Sequence[Shape], lz: Array, period: float) -> ShapeDistances:
        """Every shape of this class against m points ``lz`` (m, 2)."""
        rows = []
        for shape in shapes:
            d, n = shape.point_distance(lz, period)
            e, ge = shape.penalty(d, n)
            rows.append((d, n, e, ge, np.zeros_like(d)))
        return ShapeDistances(*(np.stack([r[i] for r in rows]) for i in range(5)))

    @classmethod
    def batch_segments(
        cls, shapes: Sequence[Shape], a: Array, b: Array, period: float
    ) -> ShapeDistances:
        """Every shape of this class against m segments from ``a`` to ``b`` (each (m, 2))."""
        rows = []
        for shape in shapes:
            d, t, n = shape.segment_distance(a, b, period)
            e, ge = shape.penalty(d, n)
            rows.append((d, n, e, ge, t))
        return ShapeDistances(*(np.stack([r[i] for r in rows]) for i in range(5)))


def wrap_l(dl: Array, period: float) -> Array:
    """Arc-length differences wrapped into ``[−period/2, period/2)``, m."""
    return np.remainder(dl + 0.5 * period, period) - 0.5 * period


def local(lz: Array, l_ref: float, period: float) -> Array:
    """Points ``lz`` (m, 2) with l measured from ``l_ref``, wrapped: ``[Δl, z]``."""
    out = np.array(lz, dtype=np.float64)
    out[:, 0] = wrap_l(out[:, 0] - l_ref, period)
    return out


def local_segments(a: Array, b: Array, l_ref: float, period: float) -> tuple[Array, Array]:
    """Segments in the frame of :func:`local`, ``b`` unwrapped from ``a`` (the short way)."""
    la = local(a, l_ref, period)
    lb = np.array(b, dtype=np.float64)
    lb[:, 0] = la[:, 0] + wrap_l(lb[:, 0] - np.asarray(a)[:, 0], period)
    return la, lb
