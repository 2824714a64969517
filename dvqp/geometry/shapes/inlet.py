"""A branch inlet: a perpendicular tube of radius r meeting the pipe, as seen developed.

A tube of radius ``r < R`` whose axis meets the pipe axis at ``(l0, z0)`` at a right angle
cuts the pipe surface along ``(R sin((l − l0)/R))² + (z − z0)² = r²``: a circle stretched in l,
``Δl = R asin(r cos φ / R)``, ``Δz = r sin φ``. The outline is represented by a polygon of
:data:`VERTICES` points on that curve, whose chords lie within ``r (1 − cos(π/N))`` of it
(5.6 µm for r = 7.5 cm): distances are exact to that.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from dvqp import _validate
from dvqp.errors import ParameterError
from dvqp.geometry.shapes.polygon import Polygon
from dvqp.geometry.shapes.shape import Array, Shape

VERTICES = 256
"""Points of the polygon that stands for the outline."""


@dataclass(frozen=True, eq=False)
class Inlet(Shape):
    """A branch tube meeting the pipe at a right angle.

    Parameters
    ----------
    center
        ``[l0, z0]``, m: where the branch axis meets the pipe axis.
    radius
        ``r``, m, ``0 < r < pipe_radius``.
    pipe_radius
        ``R``, m.
    weight
        The objective weight ``w_j`` (>= 0).
    """

    center: NDArray[np.float64]
    radius: float
    pipe_radius: float
    weight: float = 1.0
    kind: ClassVar[str] = "inlet"
    SCENE_FIELDS: ClassVar[dict[str, tuple[str, Any]]] = {
        "center": ("point", None), "radius": ("length", None), "weight": ("weight", 1.0),
    }  # fmt: skip
    polygon: Polygon = field(init=False, repr=False)

    def __post_init__(self) -> None:
        center = _validate.readonly(_validate.vector("center", self.center, 2))
        object.__setattr__(self, "center", center)
        r = _validate.positive("radius", self.radius)
        big = _validate.positive("pipe_radius", self.pipe_radius)
        if not r < big:
            raise ParameterError("radius", f"{r:g} m must be smaller than the pipe radius "
                                 f"{big:g} m")  # fmt: skip
        object.__setattr__(self, "radius", r)
        object.__setattr__(self, "weight", _validate.positive("weight", self.weight, strict=False))
        object.__setattr__(self, "polygon", Polygon(self.curve(VERTICES), self.weight))

    def curve(self, count: int) -> Array:
        """``count`` points of the exact outline, counter-clockwise, not closed, m."""
        phi = np.linspace(0.0, 2.0 * np.pi, count, endpoint=False)
        r, big = self.radius, self.pipe_radius
        dl = big * np.arcsin(r * np.cos(phi) / big)
        return self.center + np.column_stack([dl, r * np.sin(phi)])

    @classmethod
    def from_scene(cls, values: dict[str, Any], pipe_radius: float) -> Inlet:
        """From a scene file's ``[[obstacles]]`` table (keys :attr:`SCENE_FIELDS`)."""
        return cls(values["center"], values["radius"], pipe_radius, values["weight"])

    @property
    def size(self) -> float:
        """The branch radius r, m."""
        return self.radius

    @property
    def z_range(self) -> tuple[float, float]:
        """``z0 ± r``, m."""
        return float(self.center[1] - self.radius), float(self.center[1] + self.radius)

    def outline(self) -> Array:
        """512 points of the exact outline, closed."""
        points = self.curve(512)
        return np.vstack([points, points[:1]])
