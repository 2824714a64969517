"""Random scenes of ``dvqp bench``: deterministic per seed and index, all valid, all varied."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from dvqp import load_scene
from dvqp.bench import generate_scene, generate_scenes, save_scenes
from dvqp.bench.motion import MAX_STEPS
from dvqp.bench.obstacles import SHAPE_ORDER
from dvqp.bench.toml_text import dumps, value_text
from dvqp.errors import ParameterError
from dvqp.geometry import min_clearance
from dvqp.kinematics import KinematicState
from dvqp.scenes import loads

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib


@pytest.fixture(scope="module")
def suite() -> list:
    return generate_scenes(11, 12)


def test_the_same_seed_gives_the_same_scenes_whatever_the_count(suite: list) -> None:
    assert [s.text for s in generate_scenes(11, 4)] == [s.text for s in suite[:4]]
    assert generate_scene(11, 9) == suite[9]


def test_another_seed_gives_other_scenes(suite: list) -> None:
    other = generate_scenes(12, 4)
    assert all(a.text != b.text for a, b in zip(other, suite[:4], strict=True))
    assert other[0].name == "bench-s12-0000" and suite[7].name == "bench-s11-0007"


def test_every_scene_is_accepted_and_starts_clear_of_every_obstacle(suite: list) -> None:
    for bench_scene in [*suite, *generate_scenes(3, 4)]:
        scene = loads(bench_scene.text, bench_scene.file_name)
        assert scene.name == bench_scene.name and scene.mode == bench_scene.mode
        state = KinematicState.compute(scene.robot, scene.q0, scene.pipe_radius)
        margin = tomllib.loads(bench_scene.text)["constraints"]["margin"]
        assert len(scene.obstacles) >= 1
        assert min_clearance(state, scene.obstacles) >= margin
        assert 10 <= bench_scene.steps <= 2 * MAX_STEPS


def test_the_suite_varies_shapes_modes_steps_and_starts(suite: list) -> None:
    assert {k for s in suite for k in s.shapes} == set(SHAPE_ORDER)
    assert [s.shapes[0] for s in suite[:4]] == list(SHAPE_ORDER)
    assert {s.mode for s in suite} == {"jog", "path"}
    assert len({s.dt for s in suite}) >= 2
    starts = {tuple(loads(s.text).q0) for s in suite}
    assert len(starts) == len(suite)


def test_saved_scene_files_load_as_the_same_scene(suite: list, tmp_path: Path) -> None:
    paths = save_scenes(suite[:2], tmp_path)
    assert [p.name for p in paths] == ["bench-s11-0000.toml", "bench-s11-0001.toml"]
    scene = load_scene(paths[1])
    assert scene.text == suite[1].text and scene.name == "bench-s11-0001"
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporary left


def test_bad_seed_or_count_is_refused() -> None:
    with pytest.raises(ParameterError, match="count"):
        generate_scenes(1, 0)
    with pytest.raises(ParameterError, match="seed"):
        generate_scene(-1, 0)


def test_toml_text_writes_exact_numbers_and_refuses_nan() -> None:
    doc = {
        "name": 'a "b"',
        "pipe": {"radius": np.float64(0.1) + 0.2},
        "obstacles": [{"shape": "band", "z": [0.4, 0.45]}],
        "flag": True,
        "n": np.int64(3),
    }
    text = dumps(doc, "two\nlines")
    assert text.startswith("# two\n# lines\n")
    assert tomllib.loads(text) == {
        "name": 'a "b"',
        "flag": True,
        "n": 3,
        "pipe": {"radius": 0.1 + 0.2},
        "obstacles": [{"shape": "band", "z": [0.4, 0.45]}],
    }
    with pytest.raises(ParameterError):
        value_text(float("nan"))
