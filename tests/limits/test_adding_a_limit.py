"""A new limit, added from outside the package as dvqp adds its own: its module and one entry.

The limit below keeps the probe's height above a floor with a compiled kernel of its own; it
joins the step through the same contract as dvqp's parts (a damper's rows from its kernel),
and one call (:func:`dvqp.limits.registry.register_limit`) makes scene files take its key.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import ClassVar

import numba
import numpy as np
import pytest

import dvqp
from dvqp.errors import SceneError
from dvqp.limits.damper import Distances, fresh_rows
from dvqp.limits.registry import SCENE_LIMITS, register_limit, unregister_limit
from dvqp.scenes.scene import loads
from dvqp.workspace import PartNames

ROOT = Path(__file__).resolve().parents[2]
SCENE = ROOT / "scenes" / "paper-two-inlets.toml"


@numba.njit(cache=False)
def probe_height(tool, tool_jacobian, distance, gradient, usable):  # type: ignore[no-untyped-def]
    """The probe's height ``h`` (m) and ``∂h/∂Q`` into row 0."""
    distance[0], usable[0] = tool[2], True
    for c in range(gradient.shape[1]):
        gradient[0, c] = tool_jacobian[2, c]


class ProbeFloor(dvqp.VelocityDamper):
    """``h ≥ floor`` for the probe, one damper row."""

    name = "probe_floor"
    quantity = "height"
    SCENE_KEYS: ClassVar[dict[str, str]] = {"probe_floor": "floor", "damper_gain": "gain"}

    def __init__(self, floor: float = 0.0, gain: float = 0.5) -> None:
        super().__init__(gain)
        self.floor = float(floor)

    @property
    def safe(self) -> float:
        return self.floor

    def labels(self, names: PartNames) -> tuple[str, ...]:
        return (f"{names.probe}/floor",)

    def distances(self, state: dvqp.KinematicState) -> Distances:
        distance, gradient, usable = fresh_rows(1, state.n)
        probe_height(state.tool, state.tool_jacobian, distance, gradient, usable)
        return Distances(distance, gradient, self.floor, lambda: ("probe/floor",), usable)

    def kernel(self, plan: dvqp.StepPlan) -> dvqp.Kernel:
        distance, gradient, usable = plan.damper_rows(1)
        s = plan.state
        return dvqp.Kernel(probe_height, (s.tool, s.tool_jacobian, distance, gradient, usable))


@pytest.fixture
def registered() -> Iterator[None]:
    register_limit(ProbeFloor)
    yield
    unregister_limit(ProbeFloor)


def _text(floor: float | None) -> str:
    """The paper scene with the probe lowered 3 cm along its first JOG segment."""
    text = SCENE.read_text(encoding="utf-8")
    text = text.replace("velocity = [0.06, 0.0, 0.0, 0.0]", "velocity = [0.06, 0.0, -0.03, 0.0]")
    if floor is None:
        return text
    return text.replace("[constraints]\n", f"[constraints]\nprobe_floor = {floor}\n", 1)


def test_an_unregistered_limits_key_is_refused() -> None:
    with pytest.raises(SceneError, match="probe_floor"):
        loads(_text(0.01), source="x.toml", base_dir=ROOT / "scenes")


def test_a_registered_limit_is_made_by_a_scene_and_kept_by_its_run(registered: None) -> None:
    assert SCENE_LIMITS[-1] is ProbeFloor
    scene = loads(_text(0.065), source="x.toml", base_dir=ROOT / "scenes")
    (limit,) = [x for x in scene.limits if isinstance(x, ProbeFloor)]
    assert limit.floor == 0.065 and limit.gain == 0.5
    plain = loads(_text(None), source="y.toml", base_dir=ROOT / "scenes")
    assert [type(x) for x in scene.limits] == [*(type(x) for x in plain.limits), ProbeFloor]
    traj = dvqp.plan(scene, "daqp")
    free = dvqp.plan(plain, "daqp")
    assert np.min(free.tool[:, 2]) < 0.06  # without it the probe goes below the floor
    assert np.min(traj.tool[:, 2]) >= 0.065 - limit.tolerance
    assert np.all(traj.limits_kept)


def test_a_scene_without_its_key_does_not_make_it(registered: None) -> None:
    scene = dvqp.load_scene(SCENE)
    assert not any(isinstance(x, ProbeFloor) for x in scene.limits)


def test_a_limit_whose_key_another_limit_owns_is_refused() -> None:
    class Clash(ProbeFloor):
        SCENE_KEYS: ClassVar[dict[str, str]] = {"margin": "floor"}

    with pytest.raises(dvqp.ParameterError, match="margin"):
        register_limit(Clash)
    assert Clash not in SCENE_LIMITS
