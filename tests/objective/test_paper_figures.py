"""The paper's Figs. 8 -> 9 (docs/paper.md): with the probe held still, the redundancy alone
brings the body from above the orbital level onto it, with the baseline and with the QP."""

from __future__ import annotations

import sys

import numpy as np
import pytest

from tests.runs import run, scene

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib


@pytest.mark.parametrize("backend", ["pinv", "daqp"])
def test_the_body_settles_to_the_orbital_level_while_the_probe_is_held(backend: str) -> None:
    traj = run("reconfiguration", backend)
    level = scene("reconfiguration").orbital_level  # h*, m
    error = np.abs(traj.points[:, :, 2] - level)  # body points' height error, m
    assert error[0].mean() > 0.03 and error[0].max() > 0.06  # Fig. 8: well above the level
    assert error[-1].mean() < 0.004 and error[-1].max() < 0.006  # Fig. 9: on it
    assert np.all(np.diff(error.mean(axis=1)) < 1e-6)  # settling, never rising
    assert np.abs(traj.tool[:, :3] - traj.tool[0, :3]).max() < 5e-4  # the probe held (m)
    assert traj.ok and traj.min_clearance.min() > 0.01  # round the inlets, past the margin


def test_the_qp_starts_within_qdd_max_where_the_baseline_jumps_and_both_end_alike() -> None:
    pinv, qp = run("reconfiguration", "pinv"), run("reconfiguration", "daqp")
    qdd_max = tomllib.loads(scene("reconfiguration").text)["robot"]["qdd_max"]  # rad/s²
    assert np.abs(pinv.qddot).max() > 10 * qdd_max  # from rest to full speed in a step
    assert np.all(np.abs(qp.qddot) <= qdd_max * (1 + 1e-9))
    assert np.abs(pinv.points[-1] - qp.points[-1]).max() < 1e-3  # m: the same end pose
