"""The compiled evaluation stage by stage: its stages one at a time are the whole evaluation,
what :mod:`benchmarks.floor` times one by one and a run with parts of its own calls apart."""

from __future__ import annotations

import dataclasses

import numpy as np

import dvqp
from dvqp.resolution.registry import make_resolver
from dvqp.step import Stepper, stages
from tests.runs import scene

STAGES = (stages.MEASURE, stages.LINKS, stages.OBJECTIVE, stages.DAMPERS, stages.CONCLUDE)


def loaded(name: str) -> tuple[Stepper, Stepper, np.ndarray]:
    """Two DAQP steppers of a bundled scene, each at its start, and a configuration of its
    run (a mid sample)."""
    s = scene(name)
    traj = dvqp.plan(s, "daqp")
    out = []
    for _ in range(2):
        resolver = make_resolver("daqp", s.spec())
        stepper = Stepper(s.robot, s.pipe_radius, resolver, s.q0, s.dt, s.obstacles)
        stepper.start(s.q0)
        out.append(stepper)
    return out[0], out[1], traj.q[traj.n_steps // 2]


def snapshot(stepper: Stepper) -> dict[str, np.ndarray]:
    """Copies of what the evaluation writes: the state, distances, objective, checks."""
    a = stepper.arrays
    out = {}
    for group in (a.state, a.near, a.pairs, a.objective, a.dampers, a.checks):
        for field in dataclasses.fields(group):
            value = getattr(group, field.name)
            if isinstance(value, np.ndarray):
                out[f"{type(group).__name__}.{field.name}"] = value.copy()
    out["diagnostics"] = a.diagnostics.copy()
    return out


def test_the_stages_one_at_a_time_are_the_whole_evaluation() -> None:
    for name in ("paper-two-inlets", "many-obstacles"):
        together, apart, q = loaded(name)  # the same history: rows not written are alike
        together.load(q)
        whole = snapshot(together)
        apart.arrays.state.q[:] = q
        for stage in STAGES:
            assert stages.evaluate(apart.struct, False, stage, stage) == -1
        one_by_one = snapshot(apart)
        for key, value in whole.items():
            np.testing.assert_array_equal(one_by_one[key], value, err_msg=f"{name}: {key}")


def test_a_stage_range_runs_only_its_stages() -> None:
    stepper, _, q = loaded("paper-two-inlets")
    stepper.load(q)
    objective = stepper.arrays.objective.gradient
    objective[:] = np.nan
    stages.evaluate(stepper.struct, False, stages.DAMPERS, stages.CONCLUDE)
    assert np.isnan(objective).all()  # the objective's stage did not run
    stages.evaluate(stepper.struct, False, stages.OBJECTIVE, stages.OBJECTIVE)
    assert np.isfinite(objective).all()
