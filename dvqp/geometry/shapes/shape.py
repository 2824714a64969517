"""What every obstacle shape is: a region of the developed view's (l, z) plane with a weight
and a height.

A shape is the footprint of an obstacle; its :attr:`Shape.height` (m above the pipe surface,
``inf`` by default: a wall to the sky) extrudes it into a solid, whose distance
:mod:`dvqp.geometry.solid` derives from the footprint's. Everything below is the footprint's.

A shape's signed distance ``d`` (m) is negative inside; its normal ``∇d`` is a unit vector away
from the nearest outline point. For a segment ``[a, b]`` (a link) the smallest signed distance
over the segment counts, with the parameter ``t`` of the point ``a + t (b − a)`` that has it
and the normal there, so that ``∂d/∂a = (1 − t) ∇d`` and ``∂d/∂b = t ∇d`` (the envelope
theorem). The objective's repulsion uses the penalty ``e = d (d + 2ρ)`` with ``ρ`` the shape's
:attr:`Shape.size`, negative exactly inside (for a circle of radius ``R``, the paper's
``‖S − p‖² − R²``). Differences in l are wrapped modulo ``2πR`` (``period``).

dvqp's own shapes (circle, inlet, band, polygon) are measured by compiled kernels in their
modules: each says itself how (:meth:`Shape.compiled`: its kind's kernels, which
:mod:`dvqp.geometry.measure` calls by their addresses, and its parameters), so that a run
compiles only the kinds it measures; a shape of your own derives from :class:`Shape` and
implements :meth:`Shape.point_distance` and :meth:`Shape.segment_distance` in NumPy. A
subclass of a built-in shape inherits its compiled measurement, unless it replaces those
methods.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from dvqp.errors import ParameterError

Array = NDArray[np.float64]

UNKNOWN = (math.nan, 0.0, 0.0)
"""A segment's end whose distance the caller does not have (:class:`ShapeKernels` ``segment``)."""


@dataclass(frozen=True)
class ShapeKernels:
    """A shape kind's compiled measurement: ``@njit`` kernels reading obstacle ``j``'s
    parameters from the packed :class:`~dvqp.geometry.measure.ShapeArrays` ``shapes``.

    Attributes
    ----------
    point : dispatcher
        ``point(shapes, j, pl, pz) -> (d, ∂d/∂l, ∂d/∂z)``: a point's signed distance (m) and
        normal.
    segment : dispatcher
        ``segment(shapes, j, al, az, bl, bz, a_end, b_end) -> (d, t, ∂d/∂l, ∂d/∂z)``: a
        segment's smallest signed distance, its parameter and the normal there; ``a_end``,
        ``b_end`` its ends' ``point`` values where known (else
        :data:`UNKNOWN`), if the kind uses them (``ends``).
    rows : dispatcher, optional
        ``rows(shapes, j, chain, near)``: every point's and link's exact row to obstacle j at
        once, where that is cheaper than a call a row (a circle's).
    boxed : bool
        Whether a part far from the obstacle's box may get the box's distance instead (its
        exact distance costs more than the box's).
    ends : bool
        Whether ``segment`` uses its ends' distances (a segment's ends then measured once).
    """

    point: Any
    segment: Any
    rows: Any = None
    boxed: bool = False
    ends: bool = False


@dataclass(frozen=True)
class CompiledShape:
    """How the compiled measurement reads one shape.

    Attributes
    ----------
    kernels : ShapeKernels
        Its kind's kernels.
    data : tuple of 4 floats
        Its parameters (see :class:`~dvqp.geometry.measure.ShapeArrays`).
    box : tuple of 4 floats
        ``[l_lo, l_hi, z_lo, z_hi]`` (m), l from ``data[0]``.
    samples : ndarray, shape (V, 2), optional
        Its vertices or outline samples in its local frame (m).
    convex : bool
        Whether its footprint is convex: its solid's signed distance is then convex along a
        straight segment (and along a real link, whose height is convex), which the halving
        of a link uses to drop pieces (:mod:`dvqp.geometry.link_pieces`).
    """

    kernels: ShapeKernels
    data: tuple[float, float, float, float]
    box: tuple[float, float, float, float]
    samples: Array | None = None
    convex: bool = False


class Shape(ABC):
    """An obstacle in the developed view.

    Attributes
    ----------
    kind : str
        The scene file's ``shape`` value.
    SCENE_FIELDS : dict
        The keys of its scene table: ``key -> (kind of value, default or None)``, the kinds
        being ``point`` ([l, z], m), ``length`` (m, > 0), ``interval`` ([lo, hi], m),
        ``points`` ([[l, z], ...], m), ``weight`` (>= 0) and ``height`` (m, > 0, finite;
        absent: unbounded).
    weight : float
        The objective weight ``w_j`` (>= 0).
    height : float
        How high the obstacle stands above the pipe surface, m (> 0; ``inf``, the default:
        unbounded, a wall to the sky). A part above it is clear by its height above the top.
    """

    kind: ClassVar[str] = "shape"
    SCENE_FIELDS: ClassVar[dict[str, tuple[str, Any]]] = {}
    weight: float
    height: float = math.inf

    @classmethod
    def from_scene(cls, values: dict[str, Any], pipe_radius: float) -> Shape:
        """The shape from its scene table's values (checked for type and bounds already)."""
        raise NotImplementedError(f"{cls.__name__} cannot be read from a scene file")

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

    @property
    def bounded(self) -> bool:
        """Whether the obstacle has a height (a finite one)."""
        return math.isfinite(self.height)

    def compiled(self) -> CompiledShape | None:
        """How the compiled measurement reads this shape; None (a shape of your own): its
        NumPy :meth:`point_distance` and :meth:`segment_distance`."""
        return None

    def point_distance(self, lz: Array, period: float) -> tuple[Array, Array]:
        """Signed distance ``(m,)`` and normal ``(m, 2)`` of m points ``lz`` (m, 2), for a
        shape of your own (dvqp's shapes are measured by :func:`dvqp.geometry.distances`)."""
        raise NotImplementedError(f"{type(self).__name__} has no point_distance")

    def segment_distance(self, a: Array, b: Array, period: float) -> tuple[Array, Array, Array]:
        """Smallest signed distance ``(m,)``, its parameter ``t`` ``(m,)`` and the normal there
        ``(m, 2)`` of m segments from ``a`` to ``b`` (each (m, 2)), for a shape of your own."""
        raise NotImplementedError(f"{type(self).__name__} has no segment_distance")


HEIGHT_FIELD: dict[str, tuple[str, Any]] = {"height": ("height", math.inf)}
"""The scene key every shape has: its height above the pipe surface (absent: unbounded)."""


def checked_height(value: Any) -> float:
    """``value`` as a height (m): a number > 0, finite or ``inf`` (unbounded).

    Raises
    ------
    ParameterError
        ``height``: not a real number, NaN, or not > 0.
    """
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ParameterError(
            "height", f"must be a number > 0 (m above the surface), got a {type(value).__name__}"
        )
    if not float(value) > 0.0:
        raise ParameterError("height", f"must be a number > 0 (m above the surface), got {value!r}")
    return float(value)
