"""Property: a generated robot file either loads as the tree it describes or is refused with a
DvqpError in one line — never another exception, never a crash.

Random trees of links (tests/urdf_edits.py) are loaded as drawn, or after one edit. An edit that
breaks the tree, a number, a name or a joint type must be refused by the checks, before
Pinocchio's parser sees the file; junk text or a dropped element may load or be refused. The
fuzz runs in this process: every file is checked before the parser, and the checks are what
keep a crash out.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from dvqp import DvqpError, Robot, RobotFileError
from tests.urdf_edits import EDITS, REFUSED_EDITS, Joint, arms, edit


def expected_parent(joint: Joint, joints: list[Joint]) -> str:
    """The name of the nearest joint that moves above ``joint`` ("universe" at the root)."""
    by_child = {j.child: j for j in joints}
    above = by_child.get(joint.parent)
    while above is not None and above.kind == "fixed":
        above = by_child.get(above.parent)
    return "universe" if above is None else above.name


def check_model(robot: Robot, joints: list[Joint]) -> None:
    """The loaded model is the drawn tree: its moving joints, their parents and limits."""
    model = robot.model
    moving = [j for j in joints if j.kind != "fixed"]
    assert robot.n == len(moving) == model.njoints - 1
    for joint in moving:
        index = model.getJointId(joint.name)
        assert model.names[model.parents[index]] == expected_parent(joint, joints)
        q = model.joints[index].idx_q
        if joint.kind == "continuous":
            assert robot.q_min[q] == -np.inf and robot.q_max[q] == np.inf
        else:
            assert (robot.q_min[q], robot.q_max[q]) == (joint.lower, joint.upper)
    assert all(model.existFrame(j.child) for j in joints)


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(arm=arms(), kind=st.sampled_from(("none", "none", *EDITS)), data=st.data())
def test_a_generated_robot_file_loads_as_drawn_or_is_refused_in_one_line(
    arm: tuple, kind: str, data: st.DataObject
) -> None:
    root, joints = arm
    text = edit(root, joints, kind, data)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "arm.urdf"
        path.write_text(text, encoding="utf-8")
        points = ["l0", joints[-1].child]
        try:
            robot = Robot.from_urdf(path, points, joints[-1].child)
        except DvqpError as exc:
            assert kind != "none", exc
            assert "\n" not in str(exc)
            if kind in REFUSED_EDITS:  # by the checks, not by the parser
                assert isinstance(exc, RobotFileError), exc
                assert not exc.reason.startswith("cannot load URDF"), exc
            return
    assert kind not in REFUSED_EDITS, text
    if kind == "none":
        check_model(robot, joints)
