"""A point task's rows are its body point's developed-view derivative and the velocity that
closes the gap to its target; the step writes exactly those rows."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from dvqp import (
    DvqpError,
    KinematicState,
    Objective,
    ParameterError,
    PointTask,
    QPResolver,
    Robot,
    Stepper,
    StepSpec,
    ToolTask,
)
from dvqp.kinematics.developed_view import wrap
from tests.common import PIPE_RADIUS, central_difference, random_configurations
from tests.oracles.resolution import frames

DT = 0.005
NAMES = ("l", "z", "h")


def point_of(robot: Robot, q: np.ndarray, i: int) -> np.ndarray:
    """Body point i's ``[l, z, h]`` from Pinocchio (the oracle's frames)."""
    return frames(robot, q, PIPE_RADIUS).guarded[i]


@settings(max_examples=25, deadline=None)
@given(
    st.integers(0, 4),
    st.lists(st.sampled_from(NAMES), min_size=1, max_size=3, unique=True),
    st.integers(0, 50),
)
def test_the_rows_are_the_points_derivative_and_close_the_gap(
    robot: Robot, point: int, chosen: list[str], seed: int
) -> None:
    q = random_configurations(1, seed=seed, spread=0.3)[0]
    rng = np.random.default_rng(seed)
    target = point_of(robot, q, point) + rng.normal(scale=0.01, size=3)
    target[0] += 2 * np.pi * PIPE_RADIUS  # a target a turn away is the same place
    task = PointTask(point, chosen, target, gain=3.0)
    rows = task.compute(KinematicState.compute(robot, q, PIPE_RADIUS), np.zeros(4), DT)
    index = [NAMES.index(c) for c in NAMES if c in chosen]

    def wrapped(d: np.ndarray) -> np.ndarray:
        return np.r_[wrap(d[0], PIPE_RADIUS), d[1:]]

    fd = central_difference(lambda v: point_of(robot, v, point), q, 1e-7, wrap=wrapped)
    np.testing.assert_allclose(rows.jacobian, fd[index], rtol=1e-6, atol=1e-7)
    gap = wrapped(target - point_of(robot, q, point))
    np.testing.assert_allclose(rows.velocity, 3.0 * gap[index], atol=1e-12)


def test_the_step_writes_the_tasks_rows_after_the_tool(robot: Robot, q0: np.ndarray) -> None:
    target = np.array([0.1, 0.2, 0.07])
    task = PointTask(2, ("z", "h"), target, gain=2.0, priority=2)
    spec = StepSpec((task, ToolTask()), Objective())
    s = Stepper(robot, PIPE_RADIUS, QPResolver(spec, "daqp"), q0, DT)
    s.start(q0)
    for q in (q0, random_configurations(1, seed=4, spread=0.2)[0]):
        assert s.load(q)
        s.prepare(np.array([0.01, 0.0, 0.0, 0.0]), DT)
        rows = task.compute(KinematicState.compute(robot, q, PIPE_RADIUS), np.zeros(4), DT)
        problem = s.problem()  # the tool's 4 rows first: priority 1
        np.testing.assert_array_equal(problem.A[4:], rows.jacobian)
        np.testing.assert_array_equal(problem.b[4:], rows.velocity)


def test_without_a_target_the_point_is_held_where_the_run_starts(
    robot: Robot, q0: np.ndarray
) -> None:
    spec = StepSpec((ToolTask(), PointTask(1, priority=2)), Objective())
    s = Stepper(robot, PIPE_RADIUS, QPResolver(spec, "daqp"), q0, DT)
    s.start(q0)
    q = random_configurations(1, seed=9, spread=0.1)[0]
    assert s.load(q)
    s.prepare(np.zeros(4), DT)
    start, now = point_of(robot, q0, 1), point_of(robot, q, 1)
    gap = np.r_[wrap(start[0] - now[0], PIPE_RADIUS), start[1:] - now[1:]]
    np.testing.assert_allclose(s.problem().b[4:], 5.0 * gap, atol=1e-12)


@pytest.mark.parametrize(
    ("make", "field", "words"),
    [
        (lambda: PointTask(-1), "point", "must be an integer >= 0"),
        (lambda: PointTask(1, ()), "components", "must not be empty"),
        (lambda: PointTask(1, ("x",)), "components", "unknown component 'x' (known: l, z, h)"),
        (lambda: PointTask(1, ("h", "h")), "components", "repeated"),
        (lambda: PointTask(1, priority=0), "priority", "must be an integer >= 1"),
        (lambda: PointTask(1, priority=1.5), "priority", "must be an integer >= 1"),  # type: ignore[arg-type]
        (lambda: PointTask(1, weight=0.0), "weight", "must be finite and > 0"),
        (lambda: PointTask(1, target=[0.1, 0.2]), "target", "expected shape"),
        (lambda: PointTask(1, ("h",), target=[0.1, 0.2]), "target", "expected shape"),
    ],
)
def test_bad_arguments_are_refused_naming_them(make, field: str, words: str) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(DvqpError) as info:
        make()
    assert field in str(info.value) and words in str(info.value)


def test_a_point_the_arm_does_not_have_is_refused_when_it_joins(
    robot: Robot, q0: np.ndarray
) -> None:
    spec = StepSpec((ToolTask(), PointTask(5, priority=2)), Objective())
    with pytest.raises(ParameterError, match=r"point: index 5 is out of range: .* 0 \.\. 4"):
        Stepper(robot, PIPE_RADIUS, QPResolver(spec, "daqp"), q0, DT)


def test_a_target_of_the_chosen_components_alone_is_taken_as_a_scene_file_takes_it() -> None:
    task = PointTask(2, ("h",), [0.07])
    assert task.target is not None and task.target[2] == 0.07
    both = PointTask(2, ("l", "h"), [0.3, 0.07])
    assert both.target is not None and (both.target[0], both.target[2]) == (0.3, 0.07)


def test_a_body_point_is_named_as_reports_name_it() -> None:
    assert PointTask("point3").point == PointTask(2).point == 2
    assert PointTask("point3", ("h",)).label == "point3 h"
    with pytest.raises(DvqpError, match=r"point: unknown body point 'point0'"):
        PointTask("point0")
    with pytest.raises(DvqpError, match=r"point: unknown body point 'elbow'"):
        PointTask("elbow")
