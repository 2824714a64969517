"""The body points stay above a minimum height over the pipe surface."""

from __future__ import annotations

from typing import ClassVar

import numpy as np
from numba import njit

from dvqp.errors import ParameterError
from dvqp.limits.damper import DEFAULT_DECELERATION, VelocityDamper


class SurfaceHeight(VelocityDamper):
    """``h_i ≥ h_min`` for every body point, as a damper row each (labels ``"point3/height"``;
    compiled: :func:`height_distances`).

    Parameters
    ----------
    min_height
        ``h_min``, m (finite).
    gain
        ``γ`` in (0, 1].
    deceleration
        ``a``, m/s².
    """

    name = "height"
    quantity = "height"
    SCENE_KEYS: ClassVar[dict[str, str]] = {
        "damper_deceleration": "deceleration",
        "min_height": "min_height",
        "damper_gain": "gain",
    }
    """Keys of the scene file's ``[constraints]`` table -> constructor arguments."""

    def __init__(
        self, min_height: float = 0.0, gain: float = 0.5,
        deceleration: float = DEFAULT_DECELERATION,
    ) -> None:  # fmt: skip
        super().__init__(gain, deceleration)
        if not np.isfinite(min_height):
            raise ParameterError("min_height", "must be finite")
        self.min_height = float(min_height)

    @property
    def safe(self) -> float:
        """``h_min``, m."""
        return self.min_height

    def labels(self, k: int) -> tuple[str, ...]:
        """``"point1/height"``, ... one per body point."""
        return tuple(f"point{i + 1}/height" for i in range(k))


@njit(cache=True)
def height_distances(guarded, jacobians, first, count, start, distance, gradient, usable) -> None:  # type: ignore[no-untyped-def]
    """Heights ``h`` (m) and ``∂h/∂Q`` of the guarded points ``first .. first + count − 1``
    (``guarded`` (k+1, 3), ``jacobians`` (k+1, 3, n)), from row ``start``."""
    for m in range(count):
        p, r = first + m, start + m
        distance[r], usable[r] = guarded[p, 2], True
        for c in range(gradient.shape[1]):
            gradient[r, c] = jacobians[p, 2, c]
