"""A part evaluated alone at a configuration, through the compiled step (the only
implementation dvqp has): its rows, the objective, the exact verification."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

from dvqp import (
    Bounds,
    Constraint,
    Limit,
    Objective,
    ObjectiveTerm,
    ObstacleSet,
    PseudoinverseResolver,
    QPResolver,
    Robot,
    Stepper,
    StepSpec,
    Term,
    ToolTask,
)
from dvqp.limits import Excess
from tests.common import PIPE_RADIUS

DT = 0.005


def stepper(
    robot: Robot,
    q: ArrayLike,
    *,
    limits: Sequence[Limit] = (),
    objective: Objective | None = None,
    backend: str | None = None,
    dt: float = DT,
    radius: float = PIPE_RADIUS,
    obstacles: ObstacleSet | None = None,
    tasks: Sequence = (),
) -> Stepper:
    """A stepper of the tool's DV task (and ``tasks``), ``objective`` and ``limits``, started
    at ``q``: the baseline, or a QP on ``backend``."""
    spec = StepSpec((ToolTask(), *tasks), objective or Objective(), tuple(limits))
    resolver = PseudoinverseResolver(spec) if backend is None else QPResolver(spec, backend)
    out = Stepper(robot, radius, resolver, q, dt, obstacles)
    out.start(q)
    return out


def rows(
    limit: Limit,
    robot: Robot,
    q: ArrayLike,
    dt: float = DT,
    start: ArrayLike | None = None,
    command: ArrayLike = (0, 0, 0, 0),
    radius: float = PIPE_RADIUS,
) -> Constraint | Bounds:
    """The rows ``limit`` writes at ``q`` (its run started at ``start``, default ``q``)."""
    s = stepper(
        robot, q if start is None else start, limits=[limit], backend="daqp", dt=dt, radius=radius
    )
    s.load(q)
    s.prepare(np.asarray(command, dtype=float), dt)
    return s.rows(limit)


def objective(
    terms: Objective | Sequence[ObjectiveTerm],
    robot: Robot,
    q: ArrayLike,
    radius: float = PIPE_RADIUS,
) -> Term:
    """``w`` and ``∂w/∂Q`` of ``terms`` at ``q``."""
    goal = terms if isinstance(terms, Objective) else Objective(tuple(terms))
    s = stepper(robot, q, objective=goal, radius=radius)
    return s.objective


def excess(
    limits: Sequence[Limit],
    robot: Robot,
    start: ArrayLike,
    q: ArrayLike,
    radius: float = PIPE_RADIUS,
) -> Excess:
    """The worst excess at ``q`` of ``limits`` in a run that started at ``start``."""
    s = stepper(robot, start, limits=limits, radius=radius)
    s.load(q)
    return s.excess()
