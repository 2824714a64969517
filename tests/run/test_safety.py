"""A run reported successful is safe to send: every guarded part and every limit, recomputed.

The limits are recomputed here independently of dvqp's limit code (``tests/safety.py``:
densely sampled segments, heights and tilt from the Cartesian frames).
"""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import dvqp
from dvqp.geometry import link_bends
from dvqp.geometry.bend import PRECISION
from dvqp.run.planning import final_errors
from tests import safety
from tests.runs import QP, SCENES, run, scene


def succeeded(s: dvqp.Scene, traj: dvqp.Trajectory) -> bool:
    try:
        dvqp.check_run(s, traj)
    except dvqp.DvqpError as exc:
        assert "\n" not in str(exc)
        return False
    return True


def reported_is_real(s: dvqp.Scene, q: np.ndarray, reported: float, true: float) -> bool:
    """The reported clearance is the real links' (never above it, at most PRECISION below),
    however much the links bend in the DV (``link_bends``)."""
    assert link_bends(dvqp.KinematicState.compute(s.robot, q, s.pipe_radius)).max() > 1e-4
    return bool(true - PRECISION - 1e-9 <= reported <= true + 1e-9)


@pytest.mark.parametrize("backend", QP)
def test_the_probe_stops_at_the_clamp_and_the_reported_clearance_is_true(backend: str) -> None:
    s, traj = scene("probe-into-clamp"), run("probe-into-clamp", backend)
    assert succeeded(s, traj) and "relaxed" in set(traj.status)
    probe = [safety.clearances(s, q)[1] for q in traj.q[::10]]
    assert min(probe) >= 0.01 - 0.002
    worst = int(np.argmin(traj.min_clearance))
    true, _ = safety.clearances(s, traj.q[worst])
    assert reported_is_real(s, traj.q[worst], traj.min_clearance[worst], true)
    assert traj.probe_clearance.min() >= 0.01 - 1e-4
    assert traj.task_error.max() > 0.05  # the task gave way, and says so


def test_the_baseline_drives_the_probe_through_the_clamp() -> None:
    s, traj = scene("probe-into-clamp"), run("probe-into-clamp", "pinv")
    assert not succeeded(s, traj)
    assert min(safety.clearances(s, q)[1] for q in traj.q[::10]) < -0.02


def closest_samples(reported: np.ndarray, every: int = 50, closest: int = 12) -> list[int]:
    """Every ``every``-th sample and the ``closest`` samples of least reported clearance (the
    sampled oracle costs ~0.2 s a sample)."""
    least = np.argsort(reported, kind="stable")[:closest]
    return sorted({*range(0, len(reported), every), *map(int, least)})


@pytest.mark.parametrize("backend", [b for b in ("daqp", "clarabel") if b in QP])
def test_no_part_enters_an_inlet_a_band_or_a_pad(backend: str) -> None:
    s, traj = scene("pipe-rack"), run("pipe-rack", backend)
    assert {o.kind for o in s.obstacles} == {"inlet", "band", "polygon"}
    assert succeeded(s, traj) and "relaxed" in set(traj.status)
    every = [safety.clearances(s, traj.q[k]) for k in closest_samples(traj.min_clearance)]
    assert min(c for c, _ in every) >= 0.01 - 0.001
    worst = int(np.argmin(traj.min_clearance))
    true, _ = safety.clearances(s, traj.q[worst])
    assert reported_is_real(s, traj.q[worst], traj.min_clearance[worst], true)


def test_the_baseline_drives_the_probe_into_the_pad() -> None:
    s, traj = scene("pipe-rack"), run("pipe-rack", "pinv")
    assert not succeeded(s, traj)
    samples = closest_samples(traj.probe_clearance)
    assert min(safety.clearances(s, traj.q[k])[1] for k in samples) < -0.01


@functools.cache
def paper_with_dt(dt: float) -> dvqp.Scene:
    text = (SCENES / "paper-two-inlets.toml").read_text(encoding="utf-8")
    return dvqp.scenes.loads(text.replace("dt = 0.005", f"dt = {dt}"), f"paper-dt{dt}.toml")


@pytest.mark.parametrize("backend", QP)
@pytest.mark.parametrize("dt", [0.05, 0.5, 1.0])
def test_large_steps_keep_every_limit_or_fail_with_a_reason(dt: float, backend: str) -> None:
    s = paper_with_dt(dt)
    traj = dvqp.plan(s, backend)
    if succeeded(s, traj):
        breach = safety.worst_breach(s, traj.q)  # the real links, sampled
        assert max(breach["clearance"], breach["height"], breach["probe height"]) <= 1e-3
        assert breach["tilt"] <= 1e-3 and breach["joint"] <= 1e-6


@pytest.mark.parametrize("backend", QP)
def test_a_long_weld_across_the_seam_keeps_its_heading(backend: str) -> None:
    s, traj = scene("long-weld"), run("long-weld", backend)
    assert traj.t[-1] >= 15.0 and traj.tool[0, 0] < math.pi * s.pipe_radius < traj.tool[-1, 0]
    assert succeeded(s, traj)
    position, heading = final_errors(traj)
    assert position <= 0.005 and heading <= 0.05
    assert min(safety.tilt(s, q) for q in traj.q[::20]) >= 0.2 - 1e-3


def test_without_the_tilt_limit_the_probe_turns_toward_radial() -> None:
    traj = run("long-weld", "pinv")  # the baseline holds no limit
    s = scene("long-weld")
    assert min(safety.tilt(s, q) for q in traj.q[::20]) < 0.1
    assert not succeeded(s, traj)


@settings(max_examples=12, deadline=None)
@given(
    velocity=st.tuples(
        st.floats(-0.1, 0.1), st.floats(-0.1, 0.1), st.floats(-0.05, 0.05), st.floats(-0.5, 0.5)
    ),
    duration=st.floats(0.2, 2.0),
    dt=st.sampled_from([0.01, 0.05, 0.2, 0.5]),
    backend=st.sampled_from(QP),
)
def test_no_successful_run_breaks_a_limit(
    velocity: tuple[float, float, float, float], duration: float, dt: float, backend: str
) -> None:
    text = (SCENES / "probe-into-clamp.toml").read_text(encoding="utf-8")
    start = text.index("[[motion.jog]]")
    jog = f"[[motion.jog]]\nduration = {duration!r}\nvelocity = {list(velocity)!r}\n"
    motion = text[:start].replace("dt = 0.005", f"dt = {dt}") + jog
    s = dvqp.scenes.loads(motion, "random-jog.toml")
    traj = dvqp.plan(s, backend)
    if succeeded(s, traj):
        breach = safety.worst_breach(s, traj.q)  # the real links, sampled
        assert max(breach["clearance"], breach["height"], breach["probe height"]) <= 1.2e-4
        assert breach["tilt"] <= 1e-3 and breach["joint"] <= 1e-6
