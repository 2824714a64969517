"""A tool task of some components holds those rows of ``J̄`` and of the command, in ``J̄``'s
order, whatever order they are named in."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from dvqp import (
    KinematicState,
    Objective,
    ParameterError,
    QPResolver,
    Robot,
    Stepper,
    StepSpec,
    ToolTask,
)
from tests.common import PIPE_RADIUS, Q0

DT = 0.005
NAMES = ("l", "z", "h", "alpha")


@settings(max_examples=20, deadline=None)
@given(st.lists(st.sampled_from(NAMES), min_size=1, max_size=4, unique=True))
def test_the_rows_are_the_chosen_rows_of_the_tool_jacobian(robot: Robot, chosen: list[str]) -> None:
    state = KinematicState.compute(robot, np.array(Q0), PIPE_RADIUS)
    command = np.array([0.01, -0.02, 0.003, 0.2])
    task = ToolTask(chosen)
    rows = task.compute(state, command, DT)
    index = [i for i, name in enumerate(NAMES) if name in chosen]
    np.testing.assert_array_equal(rows.jacobian, state.tool_jacobian[index])
    np.testing.assert_array_equal(rows.velocity, command[index])
    assert rows.describe() == tuple(NAMES[i] for i in index)  # type: ignore[misc]
    spec = StepSpec((task,), Objective())
    s = Stepper(robot, PIPE_RADIUS, QPResolver(spec, "daqp"), np.array(Q0), DT)
    s.start(np.array(Q0))
    s.prepare(command, DT)
    np.testing.assert_array_equal(s.problem().A, rows.jacobian)
    np.testing.assert_array_equal(s.problem().b, rows.velocity)


@pytest.mark.parametrize(
    ("components", "words"),
    [
        ((), "components: must not be empty"),
        (("l", "x"), "components: unknown component 'x' (known: l, z, h, alpha)"),
        (("l", "l"), "components: a component is repeated"),
        ("lz", "components: expected a list of names"),
    ],
)
def test_bad_components_are_refused(components: object, words: str) -> None:
    with pytest.raises(ParameterError) as info:
        ToolTask(components)  # type: ignore[arg-type]
    assert words in str(info.value)


def test_the_default_is_the_papers_task() -> None:
    assert ToolTask().components == NAMES and repr(ToolTask()) == "ToolTask()"
    assert ToolTask().label == "tool" and ToolTask(("alpha", "h")).label == "tool h, alpha"
