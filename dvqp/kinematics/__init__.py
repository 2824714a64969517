"""Kinematics: the arm on Pinocchio, the developed-view map and the per-step state."""

from dvqp.kinematics.robot import Robot
from dvqp.kinematics.state import KinematicState

__all__ = ["KinematicState", "Robot"]
