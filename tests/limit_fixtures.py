"""Obstacles, configurations and row checks shared by the limit tests."""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from dvqp import (
    Constraint,
    KinematicState,
    Obstacle,
    ObstacleSet,
    Robot,
    Scene,
    Stepper,
    load_scene,
)
from dvqp.errors import SingularConfigurationError
from dvqp.geometry import proximity
from dvqp.limits import (
    Limit,
    ObstacleDamper,
    ProbeHeight,
    SelfCollision,
    SurfaceHeight,
    TiltLimit,
    VelocityDamper,
)
from tests.common import PIPE_RADIUS
from tests.oracles.limits import closest_parts, damper_rhs, distance_jacobian, measure

DT = 0.005
ROOT = Path(__file__).resolve().parent.parent
SCENES = {"paper-two-inlets": 0.5, "pipe-rack": 0.5, "fold": 1.0}
"""Bundled scenes and the spread (rad) of random configurations that reach their margins."""
DTS = (0.001, 0.005, 0.02)


@functools.cache
def scene(name: str) -> Scene:
    """A bundled scene, read once."""
    return load_scene(ROOT / "scenes" / f"{name}.toml")


def configurations(
    robot: Robot, q0: ArrayLike, count: int, seed: int, spread: float, radius: float = PIPE_RADIUS
) -> list[NDArray[np.float64]]:
    """Uniform offsets of at most ``spread`` rad around ``q0`` (singular ones left out)."""
    rng = np.random.default_rng(seed)
    found = []
    for q in np.asarray(q0, dtype=float) + rng.uniform(-spread, spread, size=(count, robot.n)):
        try:
            KinematicState.compute(robot, q, radius)
        except SingularConfigurationError:
            continue
        found.append(q)
    return found


def clearance_of(robot: Robot, q: np.ndarray, obstacles: ObstacleSet, label: str) -> float:
    """The clearance a row's label (``<part>/<obstacle>``) names, measured by ``proximity``
    alone."""
    state = KinematicState.compute(robot, q, PIPE_RADIUS)
    near = proximity(state, obstacles)
    part, name = label.split("/")
    j = obstacles.labels.index(name)
    names = state.part_names
    if part in names.points:
        return float(near.point_clearance[j, names.points.index(part)])
    return float(near.link_clearance[j, names.links.index(part)])


def near_obstacles(state: KinematicState) -> ObstacleSet:
    """One circle 2 cm from point 3, one crossing near link 4's middle, one far away."""
    p = state.points[:, :2]
    mid = 0.5 * (p[3] + p[4])
    return ObstacleSet(
        [
            Obstacle(p[2] + np.array([0.0, 0.05]), 0.03),
            Obstacle(mid + np.array([0.0, 0.045]), 0.03),
            Obstacle(np.array([-0.5, -1.0]), 0.05),
        ]
    )


def near_set(state: KinematicState) -> ObstacleSet:
    """Circles around and on the arm: one on point 2's centre (no normal), one 0.05 mm
    inside point 3's 2 cm margin, one holding point 4 inside, one over link 4's middle, one
    grazing the probe, one far."""
    p = state.guarded[:, :2]
    return ObstacleSet(
        [
            Obstacle(p[1], 0.02),
            Obstacle(p[2] + np.array([0.0, 0.05 - 5e-5]), 0.03),
            Obstacle(p[3] + np.array([0.01, 0.0]), 0.03),
            Obstacle(0.5 * (p[3] + p[4]) + np.array([0.0, 0.035]), 0.03),
            Obstacle(p[-1] + np.array([0.0, 0.045]), 0.04),
            Obstacle(np.array([-0.5, -1.0]), 0.05),
        ]
    )


def tight_limits(state: KinematicState, deceleration: float) -> tuple[Limit, ...]:
    """Every damper, tuned so that parts sit above, within and deep below their margins."""
    return (
        ObstacleDamper(near_set(state), 0.02, 0.15, 0.7, deceleration),
        SurfaceHeight(0.08, 0.3, deceleration),
        ProbeHeight(0.06, 0.5, deceleration),
        TiltLimit(1.2, 0.5, deceleration),
        SelfCollision(0.12, 0.2, 0.5, deceleration),
    )


def damper_rows(
    stepper: Stepper,
    limit: VelocityDamper,
    q: ArrayLike,
    dt: float = DT,
    *,
    fd: bool = False,
    atol: float = 1e-12,
    gradient: bool = True,
) -> Constraint:
    """Load ``q``, prepare a step of ``dt`` and check the rows ``limit`` wrote against the
    distances it keeps, measured independently: the rows that apply (gradient defined, below
    the reach) and their labels, ``h`` by the damper rule, ``G = −∂d/∂Q`` by the old NumPy
    formula (to 1e-12) and, with ``fd`` (or where no formula is written: self-collision), by
    central differences; ``gradient=False`` skips ``G``. Returns the rows."""
    q = np.asarray(q, dtype=float)
    assert stepper.load(q)
    stepper.prepare(np.zeros(4), dt)
    radius = stepper.state.radius
    refine = None  # the links of an obstacle in several dampers: refined below the largest margin
    if isinstance(limit, ObstacleDamper):
        dampers = [d for d in stepper.resolver.spec.limits if type(d) is ObstacleDamper]
        refine = np.array(
            [
                max(d.margin for d in dampers if any(o is x for x in d.obstacles))
                for o in limit.obstacles
            ]
        )
    union, state = stepper.layout.shapes, KinematicState.compute(stepper.robot, q, radius)
    closest = closest_parts(union, state, radius) if union else None  # over the step's obstacles
    found = measure(limit, state, refine, closest)
    if found.value.shape[0] == 0:  # a damper without distances (no obstacle) has no rows;
        return Constraint(np.zeros((0, q.shape[0])), np.zeros(0))  # (Stepper.rows: the box)
    rows = stepper.rows(limit)
    assert isinstance(rows, Constraint)
    on = found.applies
    assert rows.labels == tuple(np.asarray(found.labels, dtype=object)[on])
    want = damper_rhs(
        found.value[on], found.safe[on], limit.gain, dt, limit.tolerance, limit.deceleration
    )
    np.testing.assert_allclose(rows.h, want, rtol=0, atol=atol)
    if gradient and found.gradient is not None:
        np.testing.assert_allclose(rows.G, -found.gradient[on], rtol=0, atol=1e-12)
    if gradient and (fd or found.gradient is None):
        numeric = distance_jacobian(
            limit, stepper.robot, q, radius, refine=refine, union=union or None
        )[on]
        scale = max(float(np.abs(numeric).max(initial=0.0)), 1e-3)
        np.testing.assert_allclose(-rows.G, numeric, rtol=0, atol=2e-6 * scale)
    return rows


def problem_rows(stepper: Stepper) -> int:
    """Rows of the problem's inequalities that apply (``h`` finite)."""
    problem = stepper.problem()
    return 0 if problem.h is None else int(np.isfinite(problem.h).sum())
