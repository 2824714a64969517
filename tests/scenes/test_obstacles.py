"""The scene file's obstacles: every shape, its keys, and one-line errors for bad ones."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from dvqp import SceneError
from dvqp.geometry import distances
from dvqp.geometry.shapes import Band, Circle, Inlet, Polygon
from dvqp.scenes import loads

BASE = (Path(__file__).resolve().parents[2] / "scenes" / "pipe-rack.toml").read_text(
    encoding="utf-8"
)
SRC = "scenes/x.toml"


def with_obstacles(tables: str) -> str:
    start, end = BASE.index("[[obstacles]]"), BASE.index("[constraints]")
    return BASE[:start] + tables + "\n" + BASE[end:]


def test_every_shape_is_read_with_its_keys() -> None:
    scene = loads(BASE, SRC)
    inlet, band, pad = scene.obstacles
    assert isinstance(inlet, Inlet) and inlet.radius == 0.06 and inlet.pipe_radius == 0.254
    assert isinstance(band, Band) and (band.z_min, band.z_max) == (0.46, 0.50)
    assert isinstance(pad, Polygon) and pad.vertices.shape == (4, 2)
    assert [o.weight for o in scene.obstacles] == [20.0, 20.0, 20.0]


def test_a_table_without_shape_is_a_circle_as_before() -> None:
    scene = loads(with_obstacles("[[obstacles]]\ncenter = [0.2, 0.5]\nradius = 0.05\n"), SRC)
    (circle,) = scene.obstacles
    assert isinstance(circle, Circle) and circle.weight == 1.0
    np.testing.assert_array_equal(circle.center, [0.2, 0.5])


def test_a_polygon_may_straddle_the_seam() -> None:
    edge = np.pi * 0.254
    table = (
        f'[[obstacles]]\nshape = "polygon"\nvertices = [[{edge - 0.03}, 0.6], '
        f"[{edge + 0.03}, 0.6], [{edge + 0.03}, 0.65], [{edge - 0.03}, 0.65]]\n"
    )
    (pad,) = loads(with_obstacles(table), SRC).obstacles
    period = 2 * np.pi * 0.254
    inside_either_side = np.array([[edge - 0.01, 0.62], [-edge + 0.01, 0.62]])
    d, _ = distances([pad], inside_either_side, period)
    np.testing.assert_allclose(d[0], -0.02, rtol=0, atol=1e-12)  # 2 cm from the nearest edge


BAD = [
    (
        'shape = "cone"\ncenter = [0.2, 0.5]\nradius = 0.05',
        "obstacles[0].shape: unknown shape 'cone' (known: circle, inlet, band, polygon)",
    ),
    (
        'shape = "polygon"\nvertices = [[0.4, 0.6], [0.5, 0.6]]',
        "obstacles[0].vertices: expected an array of at least 3 vertices [l, z]",
    ),
    (
        'shape = "polygon"\nvertices = [0.4, 0.6, 0.5, 0.7, 0.45]',
        "obstacles[0].vertices: expected vertices as pairs [[l, z], ...], got a flat list of 5 "
        "numbers (an odd count: not even pairs)",
    ),
    (
        'shape = "polygon"\nvertices = [0.4, 0.6, 0.5, 0.7, 0.45, 0.8]',
        "obstacles[0].vertices: expected vertices as pairs [[l, z], ...], got a flat list of 6 "
        "numbers",
    ),
    (
        'shape = "polygon"\nvertices = [[0.4, 0.6], [0.5, 0.7], [0.45, 0.8, 0.9]]',
        "obstacles[0].vertices[2]: expected an array of 2 numbers, got 3 values",
    ),
    (
        'shape = "polygon"\nvertices = [[0.4, 0.6], [0.5, 0.7], [0.5, 0.6], [0.4, 0.7]]',
        "obstacles[0].vertices: the polygon's edges cross (it must be simple)",
    ),
    (
        'shape = "inlet"\ncenter = [0.2, 0.6]\nradius = 0.3',
        "obstacles[0].radius: 0.3 m must be smaller than the pipe radius 0.254 m",
    ),
    ('shape = "band"\nz = [0.6, 0.5]', "obstacles[0].z: needs z_min < z_max, got [0.6, 0.5]"),
    ('shape = "band"\nz = [0.6, 0.7]\nradius = 0.1', "obstacles[0].radius: unknown key"),
    (
        'shape = "band"\nz = [0.30, 0.40]',
        "obstacles[0]: covers the tool's start point [l, z] = [0.2973, 0.35] m "
        "(50 mm inside the band)",
    ),
    (
        'shape = "band"\nz = [0.30, 0.40]\nheight = 0.1',
        "obstacles[0]: covers the tool's start point [l, z, h] = [0.2973, 0.35, 0.08168] m "
        "(18.3 mm inside the band)",
    ),
    *(
        (f"{table}\nheight = {value}", f"obstacles[0].height: {message}")
        for table in (
            'shape = "band"\nz = [0.6, 0.7]',
            "center = [0.2, 0.6]\nradius = 0.05",
            'shape = "inlet"\ncenter = [0.2, 0.6]\nradius = 0.05',
            'shape = "polygon"\nvertices = [[0.4, 0.6], [0.5, 0.6], [0.45, 0.7]]',
        )
        for value, message in (
            ("0.0", "must be > 0, got 0.0"),
            ("-0.01", "must be > 0, got -0.01"),
            ("nan", "must be finite, got nan"),
            ("inf", "must be finite, got inf"),
            ('"tall"', "expected a number, got a string"),
            ("[0.01, 0.02]", "expected a number, got an array"),
            ("true", "expected a number, got a boolean"),
        )
    ),
]


@pytest.mark.parametrize(
    ("table", "message"), BAD, ids=[f"{t[:12]} {m.split(': ')[1][:40]}" for t, m in BAD]
)
def test_bad_obstacles_get_one_line_naming_the_field(table: str, message: str) -> None:
    with pytest.raises(SceneError) as info:
        loads(with_obstacles("[[obstacles]]\n" + table + "\n"), SRC)
    text = str(info.value)
    assert text.startswith(f"{SRC}: {message}") and "\n" not in text
