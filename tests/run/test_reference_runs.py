"""Every bundled scene reproduces the stored runs of main before the step was composed.

``tests/data/reference_runs.npz`` holds the joint trajectories, objective values, clearances,
task errors and statuses of each bundled scene on the baseline and on the two exact active-set
backends, written by ``tests/data/make_reference_runs.py`` at commit 4a597ea and rewritten on
purpose since (see there): each run now ends with its braking steps, at rest.
"""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np
import pytest

from tests.runs import run

DATA = Path(__file__).resolve().parents[1] / "data" / "reference_runs.npz"
NAMES = (
    "joint-limit",
    "many-obstacles",
    "narrow-passage",
    "paper-two-inlets",
    "weld-circumference",
)
FIELDS = ("q", "qdot", "w", "min_clearance", "task_error")


@functools.cache
def stored() -> dict[str, np.ndarray]:
    with np.load(DATA) as data:
        return {key: data[key] for key in data.files}


@pytest.mark.parametrize("backend", ["pinv", "daqp", "quadprog"])
@pytest.mark.parametrize("name", NAMES)
def test_bundled_scene_reproduces_the_stored_run(name: str, backend: str) -> None:
    if backend != "pinv":
        pytest.importorskip(backend)
    traj = run(name, backend)  # the session's run of the scene, shared with other tests
    ref = stored()
    for field in FIELDS:
        expected = ref[f"{name}/{backend}/{field}"]
        actual = np.asarray(getattr(traj, field))
        assert actual.shape == expected.shape, field
        np.testing.assert_allclose(actual, expected, rtol=0, atol=1e-9, err_msg=field)
    assert list(traj.status) == list(ref[f"{name}/{backend}/status"])
