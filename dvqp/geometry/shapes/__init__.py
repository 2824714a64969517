"""Obstacle shapes in the developed view, one per module, and the list of them.

Adding a shape: a new module with a :class:`Shape` subclass, its ``kind`` in :data:`SHAPES`
(the scene file reads its keys in :mod:`dvqp.scenes.obstacles`), and its compiled distances in
:mod:`dvqp.geometry.measure`.
"""

from dvqp.geometry.shapes.band import Band
from dvqp.geometry.shapes.circle import Circle
from dvqp.geometry.shapes.inlet import Inlet
from dvqp.geometry.shapes.polygon import Polygon
from dvqp.geometry.shapes.shape import Shape

SHAPES: dict[str, type[Shape]] = {cls.kind: cls for cls in (Circle, Inlet, Band, Polygon)}
"""Every shape a scene file may name, by its ``shape`` value."""

__all__ = ["SHAPES", "Band", "Circle", "Inlet", "Polygon", "Shape"]
