"""A saddle weld: the probe's path round a branch, offset outward from the weld, developed.

A branch tube of radius ``r`` whose axis meets the pipe axis (radius ``R``) at ``(l0, z0)``
at a right angle is welded to the pipe along the intersection of the two cylinders,
``l = l0 + R asin(r cos θ / R)``, ``z = z0 + r sin θ``. The probe scans at the distance ``d``
outward from the branch wall: on the intersection of the pipe with the coaxial cylinder of
radius ``ρ = r + d``, ``l = l0 + R asin(ρ cos θ / R)``, ``z = z0 + ρ sin θ``: the same curve
for the larger radius, exact, and ``d`` from the branch wall measured perpendicular to the
branch axis. :class:`SaddleWeld` samples it densely enough that the polyline lies within
:data:`CHORD_TOLERANCE` of it, and makes the :class:`~dvqp.motion.path.ToolPath` the tool
follows.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from dvqp import _validate
from dvqp.errors import ParameterError
from dvqp.motion.path import ToolPath

Array = NDArray[np.float64]

CHORD_TOLERANCE = 1e-4
"""m: every point of the offset curve lies within this of the waypoints' polyline."""
TURN_SLACK = 1e-3
"""rad: an arc may exceed a full turn by this much (``[-1.5708, 4.7124]`` is one turn)."""
HEADINGS = {"along": 0.0, "across": 0.5 * math.pi}
"""The probe heading relative to the direction of travel along the curve, rad."""


@dataclass(frozen=True)
class SaddleWeld:
    """The scanning curve round a branch, offset outward from its weld.

    Parameters
    ----------
    center : array_like, shape (2,)
        ``[l0, z0]``, m: where the branch axis meets the pipe axis.
    radius, pipe_radius : float
        The branch's ``r`` and the pipe's ``R``, m.
    offset : float
        ``d >= 0``, m: the scanning distance outward from the branch wall; ``r + d < R``.
    arc : tuple of float
        ``(θ_start, θ_end)``, rad, ``0 < |θ_end − θ_start| <= 2π``: the part of the curve,
        run from ``θ_start`` to ``θ_end`` (counter-clockwise in (l, z) if ``θ_end`` is larger).
        ``θ = 0`` is the side toward +l, ``π/2`` toward +z.
    heading : str
        ``"along"``: the probe points along the curve in the direction of travel (α the
        tangent's direction, atan2(dz, dl)); ``"across"``: that turned by +π/2.
    height : float
        The probe's height ``h`` above the surface, m.
    """

    center: Array
    radius: float
    pipe_radius: float
    offset: float
    arc: tuple[float, float]
    heading: str
    height: float

    def __post_init__(self) -> None:
        object.__setattr__(
            self, "center", _validate.readonly(_validate.vector("center", self.center, 2))
        )
        _validate.positive("radius", self.radius)
        _validate.positive("offset", self.offset, strict=False)
        _validate.positive("height", self.height, strict=False)
        if not self.radius + self.offset < self.pipe_radius:
            raise ParameterError(
                "offset",
                f"the scanning radius r + d = "
                f"{self.radius + self.offset:g} m must be smaller than the "
                f"pipe radius {self.pipe_radius:g} m",
            )
        start, end = (float(a) for a in self.arc)
        if not 0.0 < abs(end - start) <= 2.0 * math.pi + TURN_SLACK:
            raise ParameterError(
                "arc", f"needs 0 < |θ_end − θ_start| <= 2π, got [{start:g}, {end:g}]"
            )
        object.__setattr__(self, "arc", (start, end))
        if self.heading not in HEADINGS:
            raise ParameterError(
                "heading", f"unknown heading {self.heading!r} (known: {', '.join(HEADINGS)})"
            )

    def points(self, theta: Array) -> Array:
        """``[l, z, h, α]`` of the probe at the curve parameters ``theta`` (rad, shape (m,)),
        shape (m, 4); α unwrapped along ``theta`` (continuous through 2π)."""
        theta = np.asarray(theta, dtype=float)
        rho, big = self.radius + self.offset, self.pipe_radius
        k = rho * np.cos(theta) / big
        dl = -rho * np.sin(theta) / np.sqrt(1.0 - k * k)  # dl/dθ
        dz = rho * np.cos(theta)
        way = math.copysign(1.0, self.arc[1] - self.arc[0])
        alpha = np.unwrap(np.arctan2(way * dz, way * dl)) + HEADINGS[self.heading]
        l, z = self.center[0] + big * np.arcsin(k), self.center[1] + rho * np.sin(theta)
        return np.column_stack([l, z, np.full_like(theta, self.height), alpha])

    def waypoints(self) -> Array:
        """The arc sampled at equal steps of θ, shape (m, 4): the fewest steps, doubling from
        64 a turn, whose chords lie within :data:`CHORD_TOLERANCE` of the curve.

        A chord's largest distance from the curve is taken at its mid-parameter point, and
        that is kept to half the tolerance: the true largest distance differs from it only
        to a higher order in the step (``tests/motion/test_saddle_weld.py`` measures it on a dense
        sampling).
        """
        start, end = self.arc
        count = max(4, math.ceil(64 * abs(end - start) / (2.0 * math.pi)))
        while True:
            theta = np.linspace(start, end, count + 1)
            if chord_deviation(self, theta) <= 0.5 * CHORD_TOLERANCE or count >= 1 << 20:
                return self.points(theta)
            count *= 2

    def path(self, speed: float, **keys: float) -> ToolPath:
        """The :class:`ToolPath` along :meth:`waypoints` at ``speed`` (m/s); ``keys``: its
        ``gain``, ``tolerance`` and ``heading_tolerance``."""
        return ToolPath(_validate.readonly(self.waypoints()), speed, **keys)


def chord_deviation(weld: SaddleWeld, theta: Array) -> float:
    """The largest distance (m) from the curve's point at each mid-parameter to the chord
    between the samples ``theta`` (rad, shape (m,)) around it, in the (l, z) plane."""
    ends = weld.points(theta)[:, :2]
    mid = weld.points(0.5 * (theta[1:] + theta[:-1]))[:, :2]
    a, b = ends[:-1], ends[1:]
    ab = b - a
    t = np.clip(
        np.sum((mid - a) * ab, axis=1) / np.maximum(np.sum(ab * ab, axis=1), 1e-300), 0.0, 1.0
    )
    return float(np.max(np.linalg.norm(a + t[:, None] * ab - mid, axis=1)))
