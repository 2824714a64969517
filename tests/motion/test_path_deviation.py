"""A run's distance from its path: exactly the all-pairs comparison's, in time about linear in
the run's length (the saddle weld at h = 9.9, 52 000 samples against 52 000 segments, took
3 minutes to sum up), and a run made long by a slip (a path at 1e-6 m/s) is announced, with
what makes it long, before it starts."""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from dvqp.cli import main
from dvqp.motion import deviation
from dvqp.motion.schedule import path_deviation
from tests.cli.test_cli import write_scene


def all_pairs(reference: np.ndarray, tool: np.ndarray) -> np.ndarray:
    """The comparison of every sample with every segment (dvqp 0.2's path_deviation)."""
    start, step = reference[:-1, :3], np.diff(reference[:, :3], axis=0)
    if start.shape[0] == 0:
        start, step = reference[:1, :3], np.zeros((1, 3))
    length2 = np.einsum("ij,ij->i", step, step)
    safe = np.where(length2 > 0.0, length2, 1.0)
    out = np.empty(tool.shape[0])
    chunk = max(1, 2**20 // start.shape[0])
    for s in range(0, tool.shape[0], chunk):
        p = tool[s : s + chunk, None, :3] - start[None]
        along = np.clip(np.einsum("bij,ij->bi", p, step) / safe, 0.0, 1.0)
        p -= along[..., None] * step
        out[s : s + chunk] = np.sqrt(np.einsum("bij,bij->bi", p, p).min(axis=1))
    return out


def saddle(samples: int, h: float = 9.9) -> tuple[np.ndarray, np.ndarray]:
    """A saddle weld's path at height ``h`` (``samples`` rows) and a run that stayed on the
    pipe, near the weld in (l, z): unreachable, far from the path all the way."""
    theta = np.linspace(-np.pi / 2, 3 * np.pi / 2, samples)
    path = np.column_stack(
        [0.3 + 0.05 * np.cos(theta), 0.4 + 0.05 * np.sin(theta), np.full(samples, h), theta]
    )
    wobble = 0.01 * np.sin(7 * theta)
    tool = path + np.column_stack([wobble, wobble, np.full(samples, 0.08 - h), 0 * theta])
    return path, tool


coordinates = st.floats(-5.0, 5.0, allow_nan=False)


@settings(max_examples=300, deadline=None)
@given(
    path=arrays(np.float64, st.tuples(st.integers(1, 80), st.just(4)), elements=coordinates),
    tool=arrays(np.float64, st.tuples(st.integers(1, 60), st.just(4)), elements=coordinates),
    scale=st.sampled_from([1e-4, 1.0, 100.0]),
    repeats=st.booleans(),
)
def test_the_deviation_is_the_all_pairs_one_to_the_last_bit(
    path: np.ndarray, tool: np.ndarray, scale: float, repeats: bool
) -> None:
    path = np.cumsum(path * scale, axis=0)  # a walk: segments of every length and direction
    if repeats:
        path = np.repeat(path, 2, axis=0)  # zero-length segments
    assert np.array_equal(path_deviation(path, tool), all_pairs(path, tool))


def test_paths_far_off_with_long_and_short_segments_agree_to_the_last_bit() -> None:
    rng = np.random.default_rng(36)
    for _ in range(40):
        n = int(rng.integers(2, 400))
        steps = rng.normal(size=(n, 4)) * rng.choice([1e-6, 1e-2, 1.0], size=(n, 1))
        path = np.cumsum(steps, axis=0)
        tool = rng.normal(size=(int(rng.integers(1, 300)), 4)) * rng.choice([1e-3, 1.0, 1e3])
        assert np.array_equal(path_deviation(path, tool), all_pairs(path, tool))
    path, tool = saddle(3000)
    assert np.array_equal(path_deviation(path, tool), all_pairs(path, tool))


def test_a_non_finite_sample_has_no_deviation_and_spoils_no_other() -> None:
    path, tool = saddle(200)
    tool[17, 1] = np.nan
    found = path_deviation(path, tool)
    assert np.isnan(found[17]) and np.isfinite(np.delete(found, 17)).all()
    assert np.array_equal(np.delete(found, 17), all_pairs(path, np.delete(tool, 17, axis=0)))


def winding(samples: int, h: float = 9.9) -> tuple[np.ndarray, np.ndarray]:
    """A weld winding along the pipe at height ``h``, 0.2 mm a step, as long as ``samples``
    make it, and a run that stayed on the pipe near it in (l, z): unreachable all the way."""
    z = 2e-4 * np.arange(samples)
    path = np.column_stack([0.05 * np.sin(z / 0.05), z, np.full(samples, h), 0 * z])
    tool = path + np.column_stack([0.01 * np.sin(7 * z / 0.05), 0 * z, 0.08 - h + 0 * z, 0 * z])
    return path, tool


def pairs_measured(monkeypatch: pytest.MonkeyPatch, run: tuple[np.ndarray, np.ndarray]) -> float:
    """Segment distances computed per sample of ``run`` (path, tool)."""
    counted = [0]
    real = deviation.segment_distances

    def counting(points: np.ndarray, start: np.ndarray, step: np.ndarray) -> np.ndarray:
        counted[0] += points.shape[0]
        return real(points, start, step)

    monkeypatch.setattr(deviation, "segment_distances", counting)
    path_deviation(*run)
    return counted[0] / run[1].shape[0]


def test_the_work_per_sample_does_not_grow_with_the_runs_length(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    short = pairs_measured(monkeypatch, winding(4_000))
    long = pairs_measured(monkeypatch, winding(32_000))
    assert long < 1.3 * short and long < 500  # the all-pairs comparison: 32 000 a sample


def test_a_finer_sampled_path_costs_at_most_the_root_of_its_refinement(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Near-equidistant segments (a curve seen from off it) are told apart by exact
    distances only: their number grows as the root of the sampling, not with it."""
    coarse = pairs_measured(monkeypatch, saddle(4_000))
    fine = pairs_measured(monkeypatch, saddle(32_000))
    assert fine < 1.3 * np.sqrt(8.0) * coarse and fine < 1_000


def test_the_unreachable_saddle_runs_report_takes_seconds() -> None:
    path, tool = saddle(52_000)
    started = time.perf_counter()
    found = path_deviation(path, tool)
    took = time.perf_counter() - started
    print(f"52 000 samples against 52 000 segments in {took:.2f} s")
    assert took < 20.0  # 0.5 to 3 s here; the all-pairs comparison took 110 s
    assert found.min() >= 9.9 - 0.08 - 1e-12


SLOW = (  # a 5 cm weld at 1 µm/s: 5e4 s of motion
    "[motion.path]\nwaypoints = [[0.30, 0.35, 0.082, 0.0], [0.35, 0.35, 0.082, 0.0]]\nspeed = 1e-6"
)


def test_a_path_made_long_by_its_speed_is_announced_with_its_motion_before_it_runs(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    def interrupted(*args: object, **kwargs: object) -> None:
        raise KeyboardInterrupt  # stop where the run would start

    monkeypatch.setattr(sys.modules["dvqp.cli.main"], "plan", interrupted)
    scene = write_scene(tmp_path, motion=SLOW)
    assert main(["plan", scene, "--backend", "pinv"]) == 130
    assert capsys.readouterr().err == (
        f"dvqp: note: {scene}: about 1e+07 steps (14 h of motion in steps of 0.005 s): roughly "
        "17 min and 12 GB\ndvqp: interrupted\n"
    )
    monkeypatch.setattr("dvqp.cli.progress.physical_memory", lambda: 8_000_000_000)
    assert main(["plan", scene, "--backend", "pinv"]) == 2
    assert capsys.readouterr().err == (
        f"dvqp: {scene}: motion: about 1e+07 steps (14 h of motion in steps of 0.005 s): "
        "roughly 17 min and 12 GB, more than this machine's 8 GB allow: use a larger dt or a "
        "shorter motion\n"
    )
