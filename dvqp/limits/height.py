"""Heights over the pipe surface: the body points above a minimum, the probe out of the wall.

Both are dampers of the guarded points' height ``h`` (m), ``∂h/∂Q`` the third row of their DV
Jacobian (compiled: :func:`height_distances`).
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np
from numba import njit

from dvqp.errors import ParameterError
from dvqp.limits.damper import DEFAULT_DECELERATION, VelocityDamper


class SurfaceHeight(VelocityDamper):
    """``h_i ≥ h_min`` for every body point, one damper row each (``"point3/height"``).

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
        "damper_deceleration": "deceleration", "min_height": "min_height", "damper_gain": "gain"
    }  # fmt: skip

    def __init__(
        self, min_height: float = 0.0, gain: float = 0.5,
        deceleration: float = DEFAULT_DECELERATION,
    ) -> None:  # fmt: skip
        super().__init__(gain, deceleration)
        self.min_height = _finite("min_height", min_height)

    @property
    def safe(self) -> float:
        """``h_min``, m."""
        return self.min_height

    def labels(self, k: int, rail: bool = False) -> tuple[str, ...]:
        """``"point1/height"``, ... one per body point."""
        return tuple(f"point{i + 1}/height" for i in range(k))


class ProbeHeight(VelocityDamper):
    """``h_tool ≥ floor`` for the probe (the tool point), one damper row ``"probe/height"``.

    The body points keep ``min_height`` (:class:`SurfaceHeight`); the probe, which inspects the
    surface, only has to stay out of the pipe wall.

    Parameters
    ----------
    floor
        Lowest probe height, m (default 0: touching the surface is allowed).
    gain
        ``γ`` in (0, 1].
    deceleration
        ``a``, m/s².
    """

    name = "probe_height"
    quantity = "height"
    SCENE_KEYS: ClassVar[dict[str, str]] = {
        "damper_deceleration": "deceleration", "damper_gain": "gain"
    }  # fmt: skip

    def __init__(
        self, floor: float = 0.0, gain: float = 0.5, deceleration: float = DEFAULT_DECELERATION
    ) -> None:
        super().__init__(gain, deceleration)
        self.floor = _finite("floor", floor)

    @property
    def safe(self) -> float:
        """``floor``, m."""
        return self.floor

    def labels(self, k: int, rail: bool = False) -> tuple[str, ...]:
        """``("probe/height",)``."""
        return ("probe/height",)


def _finite(name: str, value: float) -> float:
    if not np.isfinite(value):
        raise ParameterError(name, "must be finite")
    return float(value)


@njit(cache=True)
def height_distances(guarded, jacobians, first, count, start, distance, gradient, usable) -> None:  # type: ignore[no-untyped-def]
    """Heights ``h`` (m) and ``∂h/∂Q`` of the guarded points ``first .. first + count − 1``
    (``guarded`` (k+1, 3), ``jacobians`` (k+1, 3, n)), from row ``start``."""
    for m in range(count):
        p, r = first + m, start + m
        distance[r], usable[r] = guarded[p, 2], True
        for c in range(gradient.shape[1]):
            gradient[r, c] = jacobians[p, 2, c]
