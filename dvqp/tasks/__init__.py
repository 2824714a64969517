"""Tasks: what the joint velocities should do, hard (an equality) or soft (a cost)."""

from dvqp.tasks.task import Task, TaskRows
from dvqp.tasks.tool_dv import ToolTask

__all__ = ["Task", "TaskRows", "ToolTask"]
