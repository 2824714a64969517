"""Tasks: what the joint velocities should do, hard (an equality at a priority) or soft (a cost)."""

from dvqp.tasks.frame import FrameTask
from dvqp.tasks.point import PointTask
from dvqp.tasks.posture import PostureTask
from dvqp.tasks.task import Deviation, Samples, Task, TaskRows
from dvqp.tasks.tool_dv import ToolTask

__all__ = [
    "Deviation",
    "FrameTask",
    "PointTask",
    "PostureTask",
    "Samples",
    "Task",
    "TaskRows",
    "ToolTask",
]
