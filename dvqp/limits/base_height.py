"""The base of an arm that stands on the pipe, and its base link, out of the pipe wall.

An arm read from a URDF file and placed off the pipe axis without a rail stands on the pipe:
its base (the root link's frame) is guarded as its lead point, and the base link from it to
the first body point as its lead link (:class:`~dvqp.kinematics.Robot`, ``base_frame``).
Both keep the obstacles' margins (:class:`~dvqp.limits.ObstacleDamper` measures every guarded
part) and the pipe's surface, ``h ≥ floor`` (default 0): the base's height, and its link's
lowest point (the chord dips below its ends; :mod:`dvqp.limits.height`). ``min_height`` is the
body's: a base mounted on the surface may stand lower.
"""

from __future__ import annotations

from typing import ClassVar

from dvqp.kinematics.state import KinematicState
from dvqp.limits.damper import DEFAULT_DECELERATION, Distances, VelocityDamper
from dvqp.limits.height import finite, height_rows, join_heights
from dvqp.limits.limit import SceneLimits
from dvqp.workspace import PartNames
from dvqp.workspace.wiring import StepWiring, overrides


class BaseHeight(VelocityDamper):
    """``h ≥ floor`` for the base of an arm standing on the pipe and the lowest point of its
    base link, two damper rows (``"<base>/height"``, ``"<base>-<first point>/height"``); none
    for an arm without such a base.

    Parameters
    ----------
    floor
        Lowest height, m (default 0: the surface).
    gain
        ``γ`` in (0, 1].
    deceleration
        ``a``, m/s².
    """

    name = "base_height"
    quantity = "height"
    SCENE_KEYS: ClassVar[dict[str, str]] = {
        "damper_deceleration": "deceleration",
        "damper_gain": "gain",
    }

    def __init__(
        self, floor: float = 0.0, gain: float = 0.5, deceleration: float = DEFAULT_DECELERATION
    ) -> None:
        super().__init__(gain, deceleration)
        self.floor = finite("floor", floor)

    @classmethod
    def from_scene(cls, scene: SceneLimits) -> BaseHeight | None:
        """Made for a scene whose arm stands on the pipe (a guarded base), else None."""
        if scene.robot.base_frame is None:
            return None
        return cls(**cls.scene_arguments(scene))

    @property
    def safe(self) -> float:
        """``floor``, m."""
        return self.floor

    def labels(self, names: PartNames) -> tuple[str, ...]:
        """``("<base>/height", "<base link>/height")`` by the parts' ``names``; none without a
        base."""
        if not names.base:
            return ()
        return (f"{names.lead}/height", f"{names.links[names.k]}/height")

    def series(self, count: int, k: int, rail: bool) -> list[tuple[str, str, slice | list[int]]]:
        """The base's curve and its link's."""
        return [("height", "base", [0]), ("height", "base link", [1])] if count else []

    def distances(self, state: KinematicState) -> Distances:
        """The rows its kernels write at ``state``: the base's, then its link's chord."""
        k, base = state.k, state.part_names.base
        return height_rows(self, state, k + 1, int(base), [k] if base else [])

    def join(self, step: StepWiring) -> None:
        """Rows of the base (guarded point k + 1) and of its link's chord (link k), if the arm
        stands on the pipe."""
        if overrides(self, BaseHeight, "distances", "kernel"):
            return super().join(step)
        if step.plan.names.base:
            k = step.plan.k
            join_heights(self, step, k + 1, 1, [k])
        return None
