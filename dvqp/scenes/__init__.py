"""Scene files: a pipe, an arm, the objective, obstacles, limits and a motion, in TOML."""

from dvqp.scenes.scene import Environment, Scene, environment, load_scene, loads

__all__ = ["Environment", "Scene", "environment", "load_scene", "loads"]
