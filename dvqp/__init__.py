"""dvqp: QP-based redundancy resolution of hyper-redundant manipulators in a pipe's developed view.

The pieces, from the bottom up (one subpackage each):

- :mod:`dvqp.workspace` — the compiled step's buffers and rows (no domain knowledge);
- :mod:`dvqp.kinematics` — :class:`Robot` on Pinocchio, its compiled kinematics and the
  :class:`KinematicState` every part reads;
- :mod:`dvqp.geometry` — obstacle shapes and the body's proximity to them;
- :mod:`dvqp.tasks`, :mod:`dvqp.objective`, :mod:`dvqp.limits` — what a step is made of:
  tasks (:class:`ToolTask`, :class:`PointTask`, :class:`PostureTask`, :class:`FrameTask`,
  each at a priority), the objective ``w(Q)`` (:class:`Objective`), limits, each one
  class with its compiled kernel in its module;
- :mod:`dvqp.resolution` — :class:`StepSpec`, the QP and pseudoinverse resolvers, their names;
- :mod:`dvqp.step` — the compiled step (:class:`Stepper`) and one verified step (``advance``);
- :mod:`dvqp.motion` — JOG and path commands, :func:`simulate`, :class:`Trajectory`;
- :mod:`dvqp.scenes` — scene files;
- :mod:`dvqp.run` — the run level: :func:`plan` runs a scene with a named backend,
  :func:`export_qps` writes each QP of such a run to a file, and backends are compared
  (:mod:`dvqp.run.comparison`).
"""

from dvqp._versions import __version__
from dvqp.errors import (
    BackendError,
    DvqpError,
    InputFileError,
    LimitViolationError,
    ParameterError,
    RobotFileError,
    SceneError,
    ShapeError,
    SingularConfigurationError,
    TaskLevelError,
    UnreachableTargetError,
)
from dvqp.geometry import Obstacle, ObstacleSet
from dvqp.kinematics import KinematicState, Robot
from dvqp.limits import Bounds, Constraint, Distances, Limit, VelocityDamper
from dvqp.motion import JogSegment, ToolPath, Trajectory, jog_commands, simulate
from dvqp.objective import Objective, ObjectiveTerm, Term
from dvqp.resolution import PseudoinverseResolver, QPResolver, Resolver, StepSpec, make_resolver
from dvqp.resolution.step import Step
from dvqp.run.planning import check_run, plan
from dvqp.run.qp_export import export_qps
from dvqp.scenes import Scene, load_scene
from dvqp.step import Stepper
from dvqp.tasks import FrameTask, PointTask, PostureTask, Task, TaskRows, ToolTask
from dvqp.workspace import Kernel, PartNames, StepPlan

__all__ = [
    "BackendError",
    "Bounds",
    "Constraint",
    "Distances",
    "DvqpError",
    "FrameTask",
    "InputFileError",
    "JogSegment",
    "Kernel",
    "KinematicState",
    "Limit",
    "LimitViolationError",
    "Objective",
    "ObjectiveTerm",
    "Obstacle",
    "ObstacleSet",
    "ParameterError",
    "PartNames",
    "PointTask",
    "PostureTask",
    "PseudoinverseResolver",
    "QPResolver",
    "Resolver",
    "Robot",
    "RobotFileError",
    "Scene",
    "SceneError",
    "ShapeError",
    "SingularConfigurationError",
    "Step",
    "StepPlan",
    "StepSpec",
    "Stepper",
    "Task",
    "TaskLevelError",
    "TaskRows",
    "Term",
    "ToolPath",
    "ToolTask",
    "Trajectory",
    "UnreachableTargetError",
    "VelocityDamper",
    "__version__",
    "check_run",
    "export_qps",
    "jog_commands",
    "load_scene",
    "make_resolver",
    "plan",
    "simulate",
]
