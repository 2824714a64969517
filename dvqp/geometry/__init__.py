"""Obstacles in the developed view and the body's proximity to them."""

from dvqp.geometry.obstacle import Obstacle, ObstacleSet
from dvqp.geometry.proximity import Proximity, min_clearance, proximity

__all__ = ["Obstacle", "ObstacleSet", "Proximity", "min_clearance", "proximity"]
