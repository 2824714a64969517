"""Bundled scenes and their planned runs, loaded and run once per test session."""

from __future__ import annotations

import functools
from pathlib import Path

import dvqp

SCENES = Path(__file__).resolve().parent.parent / "scenes"
BUNDLED = tuple(sorted(p.stem for p in SCENES.glob("*.toml")))
LOOSE_ACCELERATION = {
    ("jog-priorities", "osqp"): "OSQP's relaxed posture level overshoots qdd_max by up to 2e-6 "
    "of it (its answers' tolerance; the report says every limit kept to its tolerance)"
}
"""Runs whose accelerations keep ``qdd_max`` only to :data:`LOOSE` of it, and why."""
LOOSE = 1e-5
QP = tuple(b for b in ("daqp", "clarabel", "osqp") if b in dvqp.resolution.available_resolvers())


@functools.cache
def scene(name: str) -> dvqp.Scene:
    return dvqp.load_scene(SCENES / f"{name}.toml")


@functools.cache
def run(name: str, backend: str) -> dvqp.Trajectory:
    return dvqp.plan(scene(name), backend)
