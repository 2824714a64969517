"""The compiled step reproduces the reference path, hands back what it does not do, and says so."""

from __future__ import annotations

import dataclasses
import functools

import numpy as np
import pytest

import dvqp
from dvqp.compiled.engine import compile_step
from dvqp.errors import ParameterError
from dvqp.kinematics.state import KinematicState
from dvqp.limits.excess import worst_excess
from dvqp.resolution.registry import make_resolver
from tests.common import random_configurations
from tests.runs import scene

SAMPLED = ("q", "tool", "w", "min_clearance", "probe_clearance", "tilt", "self_distance",
           "limit_excess")  # fmt: skip
STEPPED = ("qdot", "task_error")
SCENES = ("paper-two-inlets", "pipe-rack", "fold", "probe-into-clamp", "joint-limit", "long-weld",
          "urdf-arm")  # fmt: skip


@functools.cache
def runs(name: str, backend: str) -> tuple[dvqp.Trajectory, dvqp.Trajectory]:
    s = scene(name)
    return dvqp.plan(s, backend, engine="reference"), dvqp.plan(s, backend, engine="compiled")


def assert_same(name: str, ref: np.ndarray, got: np.ndarray, tol: float = 1e-12) -> None:
    """Equal to ``tol`` relative to the field's largest finite value (infinities equal)."""
    assert ref.shape == got.shape, name
    finite = np.isfinite(ref)
    np.testing.assert_array_equal(np.isfinite(got), finite, err_msg=name)
    np.testing.assert_array_equal(got[~finite], ref[~finite], err_msg=name)
    scale = max(1.0, float(np.abs(ref[finite]).max(initial=0.0)))
    np.testing.assert_allclose(got[finite], ref[finite], rtol=0, atol=tol * scale, err_msg=name)


@pytest.mark.parametrize("backend", ["pinv", "daqp"])
@pytest.mark.parametrize("name", SCENES)
def test_a_compiled_run_reproduces_the_reference_run(name: str, backend: str) -> None:
    ref, got = runs(name, backend)
    for field in SAMPLED:
        assert_same(field, getattr(ref, field), getattr(got, field))
    # The QP's answers differ by DAQP's round-off (up to 1.5e-12 rad/s measured): the compiled
    # problem keeps inactive rows (h = +inf) that the reference problem drops, so the solver
    # factors differently shaped systems; positions and every sampled value agree to 1e-12.
    for field in STEPPED:
        assert_same(field, getattr(ref, field), getattr(got, field), tol=5e-12)
    for field in ("status", "success", "substeps", "limits_kept", "iterations"):
        if field == "iterations" and backend == "daqp":
            continue  # the compiled backend keeps its own warm start
        np.testing.assert_array_equal(getattr(got, field), getattr(ref, field), err_msg=field)


@pytest.mark.parametrize("dt", [0.05, 0.5])
def test_large_and_split_steps_are_handed_to_the_reference_path(dt: float) -> None:
    """At dt 0.05 s some steps move a joint more than 0.02 rad (their straight motion is
    checked at interior points on the reference path); at 0.5 s every step does, and one is
    split into substeps."""
    text = scene("paper-two-inlets").text
    s = dvqp.scenes.loads(text.replace("dt = 0.005", f"dt = {dt}"), f"paper-dt{dt}.toml")
    ref = dvqp.plan(s, "daqp", engine="reference")
    got = dvqp.plan(s, "daqp")
    assert not ref.compiled.any()
    large = np.abs(got.qdot * dt).max(axis=1) > 0.02
    assert large.any()
    np.testing.assert_array_equal(got.compiled, ~large & (got.substeps == 1))
    np.testing.assert_array_equal(got.status, ref.status)
    np.testing.assert_array_equal(got.substeps, ref.substeps)
    np.testing.assert_array_equal(got.limits_kept, ref.limits_kept)
    for field in SAMPLED:  # the end states' figures, whichever path took the step
        assert_same(field, getattr(ref, field), getattr(got, field))


def test_relaxed_steps_are_compiled_too() -> None:
    _, got = runs("probe-into-clamp", "daqp")
    relaxed = got.status == "relaxed"
    assert relaxed.sum() > 100
    assert got.compiled[relaxed].all()


def test_the_step_of_a_bundled_scene_is_fused_into_two_generated_drivers() -> None:
    s = scene("pipe-rack")
    step = compile_step(s.robot, s.pipe_radius, make_resolver("daqp", s.spec()), s.obstacles,
                        True)  # fmt: skip
    assert step is not None
    assert step.evaluate.fused and step.prepare.fused  # type: ignore[attr-defined]


def test_the_baseline_is_compiled_on_every_step() -> None:
    _, got = runs("paper-two-inlets", "pinv")
    assert got.compiled.all()


def test_the_worst_excess_of_a_state_matches_the_reference_check() -> None:
    s = scene("pipe-rack")
    resolver = make_resolver("daqp", s.spec())
    step = compile_step(s.robot, s.pipe_radius, resolver, s.obstacles, True)
    assert step is not None
    step.start(s.q0)
    start = KinematicState.compute(s.robot, s.q0, s.pipe_radius)
    for q in random_configurations(30, seed=5, spread=0.3):
        assert step.load(q)
        ref = worst_excess(
            resolver.spec.limits, start, KinematicState.compute(s.robot, q, s.pipe_radius)
        )
        np.testing.assert_allclose(step.excess[0], ref.value, rtol=0, atol=1e-12)
        assert step.broken == ref.broken


class _PlainLimit:
    """A user's limit with no kernel: the run must take the reference path."""

    name = "plain"

    def compute(self, state: KinematicState, dt: float) -> dvqp.Bounds:
        return dvqp.Bounds(np.full(state.n, -10.0), np.full(state.n, 10.0))


def test_a_part_without_a_kernel_sends_the_run_to_the_reference_path() -> None:
    s = scene("paper-two-inlets")
    traj = dvqp.plan(s, "daqp", limits=[_PlainLimit()])
    assert traj.n_steps > 0 and not traj.compiled.any()
    with pytest.raises(ParameterError, match="engine"):
        dvqp.plan(s, "daqp", limits=[_PlainLimit()], engine="compiled")


def test_an_unknown_engine_is_refused() -> None:
    with pytest.raises(ParameterError, match="engine"):
        dvqp.plan(scene("paper-two-inlets"), "pinv", engine="fast")


class _ScaledOrbitalLevel(dvqp.objective.OrbitalLevel):
    """Overrides the math but not the kernel: its inherited kernel would be wrong."""

    def evaluate(self, state: KinematicState) -> dvqp.Term:
        term = super().evaluate(state)
        return dvqp.Term(2.0 * term.value, 2.0 * term.gradient)


def test_a_subclass_that_changes_the_math_but_not_the_kernel_is_not_compiled() -> None:
    s = scene("paper-two-inlets")
    spec = s.spec()
    terms = (_ScaledOrbitalLevel(0.08), *spec.objective.terms[1:])
    objective = dvqp.Objective(terms, gain=spec.objective.gain)
    custom = dvqp.StepSpec(spec.tasks, objective, spec.limits, spec.weights, spec.task_weight)
    resolver = make_resolver("daqp", custom)
    assert compile_step(s.robot, s.pipe_radius, resolver, s.obstacles, True) is None
    assert compile_step(s.robot, s.pipe_radius, make_resolver("daqp", spec), s.obstacles,
                        True) is not None  # fmt: skip


class _ThickSelfCollision(dvqp.limits.SelfCollision):
    """Changes the math through a private helper only: the kernel it inherits would be wrong."""

    @staticmethod
    def _geometry(state: KinematicState):  # type: ignore[no-untyped-def]
        dist, normal, s, t, pairs = dvqp.limits.SelfCollision._geometry(state)
        return dist - 0.03, normal, s, t, pairs


class _HalvingResolver(dvqp.QPResolver):
    def resolve(self, state: KinematicState, command: np.ndarray, dt: float) -> dvqp.Step:
        step = super().resolve(state, command, dt)
        return dataclasses.replace(step, qdot=0.5 * step.qdot)


def test_subclasses_of_built_in_parts_without_their_own_kernel_are_not_compiled() -> None:
    s = scene("fold")
    spec = s.spec()
    limits = tuple(_ThickSelfCollision() if isinstance(lim, dvqp.limits.SelfCollision) else lim
                   for lim in spec.limits)  # fmt: skip
    thick = dvqp.StepSpec(spec.tasks, spec.objective, limits, spec.weights, spec.task_weight)
    assert compile_step(s.robot, s.pipe_radius, make_resolver("daqp", thick), s.obstacles,
                        True) is None  # fmt: skip
    halving = _HalvingResolver(spec, "daqp")
    assert compile_step(s.robot, s.pipe_radius, halving, s.obstacles, True) is None
