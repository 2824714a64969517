"""Obstacle shapes in the developed view, one per module, and the list of them.

Adding a shape: a new module with a :class:`Shape` subclass and its ``kind`` in :data:`SHAPES`
(the scene file reads its keys in :mod:`dvqp.scenes.obstacles`); it is measured by its NumPy
methods, or by compiled kernels if it says so (:meth:`Shape.compiled`, a code that
:mod:`dvqp.geometry.measure` calls them by).
"""

from dvqp.geometry.shapes.band import Band
from dvqp.geometry.shapes.circle import Circle
from dvqp.geometry.shapes.inlet import Inlet
from dvqp.geometry.shapes.polygon import Polygon
from dvqp.geometry.shapes.shape import Shape

SHAPES: dict[str, type[Shape]] = {cls.kind: cls for cls in (Circle, Inlet, Band, Polygon)}
"""Every shape a scene file may name, by its ``shape`` value."""

__all__ = ["SHAPES", "Band", "Circle", "Inlet", "Polygon", "Shape"]
