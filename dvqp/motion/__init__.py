"""Motion: JOG segments, tool paths (a saddle weld's among them), their integration and the
recorded trajectory."""

from dvqp.motion.jog import JogSegment, jog_commands
from dvqp.motion.path import ToolPath
from dvqp.motion.saddle import SaddleWeld
from dvqp.motion.simulate import dv_error, simulate
from dvqp.motion.trajectory import Trajectory

__all__ = [
    "JogSegment",
    "SaddleWeld",
    "ToolPath",
    "Trajectory",
    "dv_error",
    "jog_commands",
    "simulate",
]
