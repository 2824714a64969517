"""The compiled verification values reproduce every limit's ``excess`` and ``worst_excess``."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import pytest

from dvqp import KinematicState, Robot
from dvqp.compiled import StepPlan
from dvqp.limits import (
    Distances,
    JointPositionLimit,
    Limit,
    ObstacleDamper,
    ProbeHeight,
    TiltLimit,
    VelocityDamper,
    worst_excess,
)
from tests.common import LINK_LENGTHS, PIPE_RADIUS
from tests.test_compiled_limits import ROOT, SCENES, Compiled, scene, states, tight_limits

Pair = tuple[KinematicState, KinematicState]


def excesses(compiled: Compiled, start: KinematicState, state: KinematicState) -> dict:
    """Per verified limit, ``max(floor − values)``; and the worst entry by ratio (key None)."""
    plan = compiled.plan
    floor = np.minimum(plan.stacked["safe"], compiled.values(start))
    over = floor - compiled.values(state)
    found: dict = {}
    for v in plan.verifications:
        found[v.limit] = over[v.slot.start : v.slot.stop].max()
        assert np.all(plan.stacked["tolerance"][v.slot.start : v.slot.stop] == v.tolerance)
        assert v.tolerance == v.limit.tolerance
    ratio = over / plan.stacked["tolerance"]
    found[None] = over[int(np.argmax(ratio))] if over.shape[0] else -math.inf
    return found


def assert_excesses(limits: Sequence[Limit], compiled: Compiled, pairs: Sequence[Pair]) -> None:
    """Every limit's excess and the worst one, compiled against the reference, to 1e-12."""
    assert not any(np.isnan(compiled.values(s)).any() for pair in pairs for s in pair)
    for start, state in pairs:
        found = excesses(compiled, start, state)
        for limit in limits:
            if not hasattr(limit, "excess"):
                continue
            want = limit.excess(start, state).value  # type: ignore[attr-defined]
            got = found.get(limit, -math.inf)  # no verifier: nothing to check
            assert got == pytest.approx(want, abs=1e-12, rel=0), type(limit).__name__
        want = worst_excess(limits, start, state).value
        assert found[None] == pytest.approx(want, abs=1e-12, rel=0)


def walks(found: Sequence[KinematicState]) -> list[Pair]:
    """Every state from each of the first three, and back."""
    return [(a, b) for a in found[:3] for b in found] + [(b, found[0]) for b in found]


@pytest.mark.parametrize("name", SCENES)
def test_a_scene_s_verification_is_its_worst_excess(name: str) -> None:
    sc = scene(name)
    limits = sc.spec().limits
    compiled = Compiled(limits, sc.robot, sc.pipe_radius)
    found = states(sc.robot, sc.q0, 8, seed=7, spread=SCENES[name], radius=sc.pipe_radius)
    assert_excesses(limits, compiled, walks(found))


@pytest.mark.parametrize("deceleration", [1.0, math.inf])
def test_starts_inside_the_margins_keep_their_floor(
    robot: Robot, state0: KinematicState, deceleration: float
) -> None:
    """Parts that start deep inside an obstacle, below their heights, tilted or folded closer
    than their margins: the floor is the start's value."""
    limits = (*tight_limits(state0, deceleration), JointPositionLimit(robot))
    compiled = Compiled(limits, robot, PIPE_RADIUS)
    found = [state0, *states(robot, state0.q, 6, seed=8, spread=0.1)]
    assert_excesses(limits, compiled, walks(found))
    start = found[0]
    values, safe = compiled.values(start), compiled.plan.stacked["safe"]
    assert np.any(values < safe - 0.01)  # some part starts deep inside its margin


def test_joint_positions_with_infinite_and_crossed_limits(q0: np.ndarray) -> None:
    q_min, q_max = q0 - 0.1, q0 + 0.1
    q_min[0], q_max[3] = -np.inf, np.inf
    q_min[5], q_max[5] = -np.inf, np.inf
    limited = Robot.ndt13(LINK_LENGTHS, q_min=q_min, q_max=q_max)
    limits = (JointPositionLimit(limited),)
    compiled = Compiled(limits, limited, PIPE_RADIUS)
    found = states(limited, q0, 6, seed=9, spread=0.2)  # starts past some limits
    assert_excesses(limits, compiled, walks(found))
    free = Robot.ndt13(LINK_LENGTHS, q_min=np.full(13, -np.inf), q_max=np.full(13, np.inf))
    compiled = Compiled((JointPositionLimit(free),), free, PIPE_RADIUS)
    found = states(free, q0, 3, seed=10, spread=0.2)
    assert_excesses((JointPositionLimit(free),), compiled, walks(found))
    assert excesses(compiled, found[0], found[1])[None] == -math.inf


def test_the_tilt_is_folded_into_zero_to_a_right_angle(
    robot: Robot, state0: KinematicState
) -> None:
    limits = (TiltLimit(0.3), TiltLimit(1.4), ProbeHeight(0.5))
    compiled = Compiled(limits, robot, PIPE_RADIUS)
    assert_excesses(limits, compiled, walks([state0, *states(robot, state0.q, 8, 11, 0.8)]))
    safe = compiled.plan.stacked["safe"]
    assert safe[:2] == pytest.approx([0.3, 1.4], abs=1e-15)


def test_every_bundled_scene_limit_compiles() -> None:
    """Each limit of each bundled scene gets a kernel and, if it verifies itself, a verifier,
    unless it adds nothing (no obstacles, ``min_tilt = 0``)."""
    for path in sorted((ROOT / "scenes").glob("*.toml")):
        sc = scene(path.stem)
        compiled = Compiled(sc.spec().limits, sc.robot, sc.pipe_radius)
        for limit in sc.spec().limits:
            adds_nothing = (isinstance(limit, TiltLimit) and limit.min_tilt == 0.0) or (
                isinstance(limit, ObstacleDamper) and not len(limit.obstacles)
            )
            assert (compiled.kernels[limit] is None) == adds_nothing, (path.stem, limit.name)
            if hasattr(limit, "excess"):
                assert (compiled.verifiers[limit] is None) == adds_nothing


def test_a_user_damper_is_not_compiled(robot: Robot) -> None:
    class Mine(VelocityDamper):
        def distances(self, state: KinematicState) -> Distances:
            return Distances(state.guarded[:, 0], state.guarded_jacobians[:, 0, :], 0.0)

    plan = StepPlan(robot.n, robot.n_points, PIPE_RADIUS)
    with pytest.raises(NotImplementedError):
        Mine().kernel(plan)
    with pytest.raises(NotImplementedError):
        Mine().verifier(plan)
