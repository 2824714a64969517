"""A scene whose every part is a trivial subclass of its built-in class (same state).

Shared by ``tests/step/test_subclassed_builtins.py`` and ``benchmarks/step_benchmark.py``
(which times its step beside the scene's own).
"""

from __future__ import annotations

import contextlib
import dataclasses
from collections.abc import Iterator

import dvqp
from dvqp.geometry.obstacle import ObstacleSet
from dvqp.scenes import scene as scene_module


def subclassed(part: object) -> object:
    """``part`` as an instance of a trivial subclass of its class (same state)."""
    cls = type(part)
    clone = object.__new__(type(f"My{cls.__name__}", (cls,), {}))
    clone.__dict__.update(part.__dict__)
    return clone


def swapped(scene: dvqp.Scene) -> tuple[dvqp.Scene, list[str]]:
    """``scene`` with every limit, objective term and obstacle a trivial subclass."""
    shapes = {id(s): subclassed(s) for s in scene.obstacles}

    def obstacles(found: ObstacleSet) -> ObstacleSet:
        clone = object.__new__(ObstacleSet)
        clone.__dict__.update(found.__dict__, obstacles=tuple(shapes[id(s)] for s in found))
        return clone

    parts = []
    for part in (*scene.limits, *scene.objective.terms):
        clone = subclassed(part)
        if "obstacles" in clone.__dict__:
            clone.__dict__["obstacles"] = obstacles(clone.__dict__["obstacles"])
        parts.append(clone)
    limits, terms = parts[: len(scene.limits)], parts[len(scene.limits) :]
    objective = dvqp.Objective(terms, scene.objective.gain)
    swapped = dataclasses.replace(
        scene, limits=tuple(limits), objective=objective, obstacles=obstacles(scene.obstacles)
    )
    return swapped, [type(p).__name__ for p in parts]


@contextlib.contextmanager
def subclassed_tool_task() -> Iterator[type]:
    """Scenes' tool task a trivial subclass of :class:`~dvqp.ToolTask` while in the block."""
    original = scene_module.ToolTask
    scene_module.ToolTask = type("MyToolTask", (original,), {})
    try:
        yield scene_module.ToolTask
    finally:
        scene_module.ToolTask = original
