"""dvqp: QP-based redundancy resolution of hyper-redundant manipulators in a pipe's developed view.

The pieces, in the order a step uses them (one subpackage each):

- :mod:`dvqp.kinematics` — :class:`Robot` on Pinocchio and the per-step :class:`KinematicState`;
- :mod:`dvqp.geometry` — :class:`Obstacle` circles and the body's proximity to them;
- :mod:`dvqp.tasks` — what the joints must do: the tool's DV task :class:`ToolTask`;
- :mod:`dvqp.objective` — ``w(Q)`` as a sum of terms, :class:`Objective`;
- :mod:`dvqp.limits` — joint, obstacle and height limits, each ``Constraint(G, h)`` or ``Bounds``;
- :mod:`dvqp.resolution` — :class:`StepSpec`, the QP built from it, the QP and pseudoinverse
  resolvers and the registry of their names;
- :mod:`dvqp.motion` — JOG and path commands, :func:`simulate`, :class:`Trajectory`;
- :mod:`dvqp.scenes` — scene files; :func:`plan` runs one with a named backend.
"""

from dvqp.errors import (
    BackendError,
    DvqpError,
    LimitViolationError,
    ParameterError,
    SceneError,
    ShapeError,
    SingularConfigurationError,
    UnreachableTargetError,
)
from dvqp.geometry import Obstacle, ObstacleSet
from dvqp.kinematics import KinematicState, Robot
from dvqp.limits import Bounds, Constraint, Limit, VelocityDamper
from dvqp.motion import JogSegment, ToolPath, Trajectory, jog_commands, simulate
from dvqp.objective import Objective, ObjectiveTerm, Term
from dvqp.planning import check_run, plan
from dvqp.resolution import (
    PseudoinverseResolver,
    QPResolver,
    Resolver,
    Step,
    StepSpec,
    build_qp,
    make_resolver,
)
from dvqp.scenes import Scene, load_scene
from dvqp.tasks import Task, TaskRows, ToolTask

__version__ = "0.2.0"

__all__ = [
    "BackendError",
    "Bounds",
    "Constraint",
    "DvqpError",
    "JogSegment",
    "KinematicState",
    "Limit",
    "LimitViolationError",
    "Objective",
    "ObjectiveTerm",
    "Obstacle",
    "ObstacleSet",
    "ParameterError",
    "PseudoinverseResolver",
    "QPResolver",
    "Resolver",
    "Robot",
    "Scene",
    "SceneError",
    "ShapeError",
    "SingularConfigurationError",
    "Step",
    "StepSpec",
    "Task",
    "TaskRows",
    "Term",
    "ToolPath",
    "ToolTask",
    "Trajectory",
    "UnreachableTargetError",
    "VelocityDamper",
    "__version__",
    "build_qp",
    "check_run",
    "jog_commands",
    "load_scene",
    "make_resolver",
    "plan",
    "simulate",
]
