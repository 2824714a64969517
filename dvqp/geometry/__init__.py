"""Obstacles in the developed view and the body's proximity to them."""

from dvqp.geometry.bend import link_bends
from dvqp.geometry.obstacle import Obstacle, ObstacleSet
from dvqp.geometry.proximity import (
    Proximity,
    distances,
    min_clearance,
    proximity,
    segment_distances,
)

__all__ = [
    "Obstacle",
    "ObstacleSet",
    "Proximity",
    "distances",
    "link_bends",
    "min_clearance",
    "proximity",
    "segment_distances",
]
