"""dvqp: QP-based redundancy resolution of hyper-redundant manipulators in a pipe's developed view.

The pieces, in the order a step uses them:

- :class:`Robot` — Pinocchio model, body-point and tool frames, joint limits;
- :class:`KinematicState` — one kinematics update per step, in Cartesian and DV coordinates;
- :class:`Objective` — the paper's ``w(Q)`` with its gradient, :class:`Obstacle` circles;
- resolvers — :class:`PseudoinverseResolver` (paper eq. 18) and the per-step QP;
- :func:`simulate` — JOG / path integration into a :class:`Trajectory`;
- :func:`load_scene` and :func:`plan` — a scene file run with a named backend.
"""

from dvqp.errors import (
    BackendError,
    DvqpError,
    ParameterError,
    SceneError,
    ShapeError,
    SingularConfigurationError,
    UnreachableTargetError,
)
from dvqp.objective import Objective, Term
from dvqp.geometry.obstacle import Obstacle
from dvqp.resolution.pinv import PseudoinverseResolver
from dvqp.planning import plan
from dvqp.resolution.step import Resolver, Step
from dvqp.kinematics.robot import Robot
from dvqp.scenes.scene import Scene, load_scene
from dvqp.motion.simulate import JogSegment, jog_commands, simulate
from dvqp.kinematics.state import KinematicState
from dvqp.motion.trajectory import Trajectory

__version__ = "0.1.0"

__all__ = [
    "BackendError",
    "DvqpError",
    "JogSegment",
    "KinematicState",
    "Objective",
    "Obstacle",
    "ParameterError",
    "PseudoinverseResolver",
    "Resolver",
    "Robot",
    "Scene",
    "SceneError",
    "ShapeError",
    "SingularConfigurationError",
    "Step",
    "Term",
    "Trajectory",
    "UnreachableTargetError",
    "__version__",
    "jog_commands",
    "load_scene",
    "plan",
    "simulate",
]
