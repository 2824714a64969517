"""Reader of a scene file's ``[[obstacles]]`` tables: one shape each, keys from the shape.

``shape`` names the kind (default ``"circle"``, so scenes written before there were other
shapes still read); the other keys are those the shape class declares in ``SCENE_FIELDS``, so
a new shape needs no change here. An optional ``name`` labels the obstacle in every report
(:attr:`~dvqp.geometry.obstacle.ObstacleSet.labels`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from dvqp.geometry.obstacle import ObstacleSet
from dvqp.geometry.shapes import SHAPES
from dvqp.scenes.fields import Fields, is_number, join
from dvqp.scenes.sections import POSITION, SIZE, WEIGHT


def obstacles(f: Fields, doc: dict[str, Any], pipe_radius: float) -> ObstacleSet:
    """``[[obstacles]]``: shapes in the (l, z) plane (none if absent)."""
    keys = ("shape", "name", *dict.fromkeys(k for cls in SHAPES.values() for k in cls.SCENE_FIELDS))
    out, names = [], []
    for i, t in enumerate(f.tables(doc, "obstacles", "", keys)):
        prefix = join("obstacles", i)
        kind = f.string(t, "shape", prefix, "circle")
        cls = SHAPES.get(kind)
        if cls is None:
            f.fail(join(prefix, "shape"), f"unknown shape {kind!r} (known: {', '.join(SHAPES)})")
        f.check_keys(t, prefix, ("shape", "name", *cls.SCENE_FIELDS))
        names.append(f.string(t, "name", prefix) if "name" in t else None)
        values = {
            key: _value(f, t, prefix, key, what, default)
            for key, (what, default) in cls.SCENE_FIELDS.items()
        }
        with f.mapped(prefix):
            out.append(cls.from_scene(values, pipe_radius))
    with f.mapped(""):  # a name's error names its field, obstacles[j].name
        return ObstacleSet(out, names)


def _value(f: Fields, t: dict[str, Any], prefix: str, key: str, kind: str, default: Any) -> Any:
    if kind in ("point", "interval"):
        return f.vector(t, key, prefix, 2, within=POSITION)
    if kind == "length":
        return f.number(t, key, prefix, within=SIZE)
    if kind == "weight":
        return f.number(t, key, prefix, default, within=WEIGHT)
    if kind == "height":  # absent: unbounded (the default); given: a finite number > 0
        return f.number(t, key, prefix, within=SIZE) if key in t else default
    raw = f.get(t, key, prefix)  # "points"
    field = join(prefix, key)
    if isinstance(raw, list) and raw and all(is_number(v) for v in raw):
        odd = " (an odd count: not even pairs)" if len(raw) % 2 else ""
        f.fail(
            field,
            f"expected vertices as pairs [[l, z], ...], got a flat list of {len(raw)} numbers{odd}",
        )
    if not isinstance(raw, list) or len(raw) < 3:
        f.fail(field, "expected an array of at least 3 vertices [l, z]")
    return np.array(
        [f.vector_value(join(field, j), p, 2, within=POSITION) for j, p in enumerate(raw)]
    )
