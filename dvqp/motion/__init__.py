"""Motion: JOG segments, tool paths, their integration and the recorded trajectory."""

from dvqp.motion.jog import JogSegment, jog_commands
from dvqp.motion.path import ToolPath
from dvqp.motion.simulate import dv_error, simulate
from dvqp.motion.trajectory import Trajectory

__all__ = ["JogSegment", "ToolPath", "Trajectory", "dv_error", "jog_commands", "simulate"]
