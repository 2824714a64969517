"""The objective ``w(Q)``: terms that add up to its value and gradient, one per module."""

from dvqp.objective.objective import Objective
from dvqp.objective.obstacle_links import ObstacleLinks
from dvqp.objective.obstacle_points import ObstaclePoints
from dvqp.objective.orbital_level import OrbitalLevel
from dvqp.objective.term import ObjectiveTerm, Term

__all__ = ["Objective", "ObjectiveTerm", "ObstacleLinks", "ObstaclePoints", "OrbitalLevel", "Term"]
