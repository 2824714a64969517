"""Property: whatever a mistaken scene file holds, ``dvqp plan`` ends in one of two ways.

The bundled scenes, their motion cut to a few steps, are mutated as people get scene files
wrong — a value of another type, a missing or unknown key, a non-finite or extreme number, an
array of the wrong length, values nested hundreds of levels deep, garbage bytes — and run
through :func:`dvqp.cli.main`; for the URDF scene, its arm's file may be edited instead
(tests/urdf_edits.py: a second parent, a cycle, a bad number or name, junk). Either the input
is refused (exit 2, exactly one ``dvqp:`` line on stderr, nothing written; a broken URDF tree,
number, name or joint type always, by the file's checks), or the run happens (exit 0 or 1, no
traceback, every stderr line a ``dvqp:`` line) and its saved arrays are finite except where
``docs/cli.md`` says otherwise: the task error of a failed step, the clearance when there is
no obstacle.
"""

from __future__ import annotations

import contextlib
import io
import json
import math
import shutil
import sys
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import numpy as np
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from dvqp import SceneError, load_scene
from dvqp.cli import main
from dvqp.cli.progress import RunEstimate
from dvqp.scenes import environment
from tests.urdf_edits import EDITS, REFUSED_EDITS, edit, joints_of

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

SCENES = Path(__file__).resolve().parents[2] / "scenes"
NAMES = ("paper-two-inlets", "joint-limit", "narrow-passage", "many-obstacles", "urdf-arm")
MAX_STEPS = 400
"""Mutations that make a valid run longer than this are not run (a long run is not a fault)."""

Doc = dict[str, Any]
Key = tuple[Any, ...]


def short(name: str) -> Doc:
    """A bundled scene as a dict, its motion cut to a few steps."""
    doc = tomllib.loads((SCENES / f"{name}.toml").read_text(encoding="utf-8"))
    motion = doc["motion"]
    if "jog" in motion:
        motion["jog"] = [dict(s, duration=3 * motion["dt"]) for s in motion["jog"][:2]]
    else:
        path = motion["path"]
        start = path["waypoints"][0]
        path["waypoints"] = [start, [start[0] + 0.01, *start[1:]]]
    return doc


def toml(value: Any) -> str:
    """``value`` as a TOML inline value (tables inline, non-finite floats as TOML writes them)."""
    if isinstance(value, Raw):
        return str(value)
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return (
            "nan"
            if math.isnan(value)
            else ("inf" if value > 0 else "-inf")
            if math.isinf(value)
            else repr(value)
        )
    if isinstance(value, int):
        return str(value)
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, list):
        return "[" + ", ".join(toml(v) for v in value) + "]"
    return "{" + ", ".join(f"{json.dumps(k)} = {toml(v)}" for k, v in value.items()) + "}"


def dumps(doc: Doc) -> str:
    return "".join(f"{json.dumps(k)} = {toml(v)}\n" for k, v in doc.items())


def places(value: Any, at: Key = ()) -> list[Key]:
    """The key path of every value below ``value`` (tables, arrays and leaves)."""
    found = []
    items = value.items() if isinstance(value, dict) else enumerate(value)
    for key, child in items:
        found.append((*at, key))
        if isinstance(child, (dict, list)):
            found.extend(places(child, (*at, key)))
    return found


def parent_of(doc: Doc, key: Key) -> Any:
    node: Any = doc
    for part in key[:-1]:
        node = node[part]
    return node


class Raw(str):
    """TOML text written as it is (values nested too deep to build as Python objects)."""


def nested(depth: int, table: bool) -> Raw:
    """``depth`` arrays (or inline tables) one inside the other, around a number."""
    return Raw("{a = " * depth + "1" + "}" * depth if table else "[" * depth + "1" + "]" * depth)


NUMBERS = st.sampled_from(
    [
        0,
        -0.0,
        1e-300,
        1e-9,
        0.001,
        0.5,
        -0.5,
        3,
        9.99,
        10.0,
        99.9,
        999.0,
        1e6,
        -1e6,
        1e300,
        -1e300,
        1.7976931348623157e308,
        math.inf,
        -math.inf,
        math.nan,
        10**400,
        -(10**30),
    ]
)
VALUES = st.one_of(
    NUMBERS,
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-(10**20), max_value=10**20),
    st.booleans(),
    st.text(max_size=8),
    st.lists(NUMBERS, max_size=6),
    st.dictionaries(st.sampled_from(["a", "radius", "dt"]), NUMBERS, max_size=2),
    st.builds(nested, st.sampled_from([3, 100, 400, 1200]), st.booleans()),
)


def mutate(doc: Doc, data: st.DataObject) -> str | bytes:
    """One mistake in ``doc``: the file text (or bytes) to run."""
    kind = data.draw(
        st.sampled_from(
            [
                "replace",
                "number",
                "number",
                "scale",
                "scale",
                "delete",
                "unknown",
                "length",
                "deep",
                "bytes",
                "splice",
            ]
        ),
        label="mistake",
    )
    if kind == "bytes":
        return data.draw(st.binary(min_size=1, max_size=64), label="garbage")
    text = dumps(doc)
    if kind == "splice":
        at = data.draw(st.integers(0, len(text)), label="at")
        junk = data.draw(st.text(min_size=1, max_size=8), label="junk")
        return text[:at] + junk + text[at:]
    keys = places(doc)
    if kind == "length":
        keys = [k for k in keys if isinstance(parent_of(doc, k)[k[-1]], list)]
    if kind in ("scale", "number"):
        keys = [k for k in keys if isinstance(parent_of(doc, k)[k[-1]], (int, float))]
    key = data.draw(st.sampled_from(keys), label="where")
    node = parent_of(doc, key)
    if kind in ("replace", "number"):
        node[key[-1]] = data.draw(VALUES if kind == "replace" else NUMBERS, label="value")
    elif kind == "scale":
        factor = data.draw(NUMBERS, label="factor")
        try:
            node[key[-1]] = node[key[-1]] * factor
        except OverflowError:  # a float times an integer of 400 digits
            node[key[-1]] = factor
    elif kind == "delete":
        del node[key[-1]]
    elif kind == "unknown":
        target = node[key[-1]] if isinstance(node[key[-1]], dict) else doc
        target[data.draw(st.sampled_from(["radus", "extra", "q_0", "jogs"]))] = 1.0
    elif kind == "length":
        values = node[key[-1]]
        node[key[-1]] = values[:-1] if data.draw(st.booleans()) else [*values, values[-1]]
    else:
        node[key[-1]] = nested(data.draw(st.sampled_from([600, 1500])), data.draw(st.booleans()))
    return dumps(doc)


def run(folder: Path, scene: Path, backend: str) -> tuple[int, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(["plan", str(scene), "--backend", backend, "-o", str(folder / "out.npz")])
    return code, err.getvalue()


def check_arrays(path: Path) -> None:
    """Every saved float array is finite, but where the documentation allows otherwise."""
    with np.load(path, allow_pickle=False) as data:
        arrays = {key: data[key] for key in data.files}
    obstacles = environment(str(arrays["scene"])).obstacles
    failed = ~arrays["success"]
    for key, value in arrays.items():
        if value.dtype.kind != "f":
            continue
        bad = ~np.isfinite(value)
        if key == "task_error":
            bad &= ~failed  # a failed step has no task error to speak of (+inf)
        if key == "level_error":
            bad &= ~failed[:, None]  # nor errors of its levels (+inf)
        if key.endswith("clearance") and not len(obstacles):
            bad &= ~np.isposinf(value)  # no obstacle: +inf
        assert not bad.any(), key


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(name=st.sampled_from(NAMES), backend=st.sampled_from(["pinv", "daqp"]), data=st.data())
def test_a_mistaken_scene_is_refused_in_one_line_or_runs_to_finite_arrays(
    name: str, backend: str, data: st.DataObject
) -> None:
    urdf_edit = name == "urdf-arm" and data.draw(st.booleans(), label="edit the URDF")
    content = dumps(short(name)) if urdf_edit else mutate(short(name), data)
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        shutil.copy(SCENES / "ndt13.urdf", folder / "ndt13.urdf")
        if urdf_edit:  # the arm's file edited instead of the scene
            kind = data.draw(st.sampled_from(EDITS), label="URDF edit")
            root = ET.parse(folder / "ndt13.urdf").getroot()
            (folder / "ndt13.urdf").write_text(edit(root, joints_of(root), kind, data), "utf-8")
        scene = folder / "scene.toml"
        if isinstance(content, bytes):
            scene.write_bytes(content)
        else:
            scene.write_text(content, encoding="utf-8")
        with contextlib.suppress(SceneError):
            assume(RunEstimate.of(load_scene(scene)).steps <= MAX_STEPS)
        code, err = run(folder, scene, backend)
        lines = err.splitlines()
        assert "Traceback" not in err and all(line.startswith("dvqp: ") for line in lines), err
        if urdf_edit and kind in REFUSED_EDITS:
            assert code == 2 and "robot.urdf: " in err and "cannot load URDF" not in err, err
        if code == 2:
            assert len(lines) == 1, err
            assert sorted(p.name for p in folder.iterdir()) == ["ndt13.urdf", "scene.toml"]
            return
        assert code in (0, 1), (code, err)
        if (folder / "out.npz").exists():
            check_arrays(folder / "out.npz")
        else:  # a run that ended in a singular configuration has nothing to save
            assert code == 1 and "singular" in err, err
