"""Compiled (numba) proximity of the guarded points and links to bands ``z ∈ [z_min, z_max]``.

The same arithmetic as :meth:`~dvqp.geometry.shapes.band.Band.point_distance` and
:meth:`~dvqp.geometry.shapes.band.Band.segment_distance`, one point or link at a time,
written straight into the plan's buffers (argument order: :mod:`.shape_kernels`).
"""

from __future__ import annotations

from numba import njit

from dvqp.geometry.shapes.shape import Array
from dvqp.geometry.shapes.shape_kernels import store

_FLAT = 1e-15


@njit(cache=True)
def _distance(z: float, z_min: float, z_max: float) -> tuple[float, float]:
    """``max(z_min − z, z − z_max)`` (m) and ``∂d/∂z`` (∓1)."""
    below, above = z_min - z, z - z_max
    return max(below, above), -1.0 if below >= above else 1.0


@njit(cache=True)
def _segment(za: float, zb: float, z_min: float, z_max: float) -> tuple[float, float, float]:
    """Smallest distance along a segment from z ``za`` to ``zb``, its ``t`` and ``∂d/∂z``
    there: the best of the two ends and the crossing of the middle line (no gradient)."""
    dz = zb - za
    crossing = (0.5 * (z_min + z_max) - za) / dz if abs(dz) > _FLAT else 0.0
    crossing = min(max(crossing, 0.0), 1.0)
    best_k, best_t = 0, 0.0
    best = max(z_min - za, za - z_max)
    for k in range(1, 3):
        t = 1.0 if k == 1 else crossing
        z = za + t * dz
        value = max(z_min - z, z - z_max)
        if value < best:
            best, best_k, best_t = value, k, t
    d, nz = _distance(za + best_t * dz, z_min, z_max)
    if best_k == 2 and 0.0 < best_t < 1.0:
        nz = 0.0
    return d, best_t, nz


@njit(cache=True)
def bands(
    guarded: Array, period: float, z_min: Array, z_max: Array, sizes: Array, indices: Array,
    point_distance: Array, point_normal: Array, point_penalty: Array, point_gradient: Array,
    link_distance: Array, link_normal: Array, link_penalty: Array, link_gradient: Array,
    link_t: Array,
) -> None:  # fmt: skip
    """Bands ``[z_min, z_max]`` (each (J,), m; half widths ``sizes``) against the k+1 points
    and k links of ``guarded`` (k+1, 3); band j's results go to row ``indices[j]``."""
    m = guarded.shape[0]
    for j in range(indices.shape[0]):
        row, lo, hi, rho = indices[j], z_min[j], z_max[j], sizes[j]
        for i in range(m):
            d, nz = _distance(guarded[i, 1], lo, hi)
            store(point_distance, point_normal, point_penalty, point_gradient, row, i,
                  d, 0.0, nz, rho)  # fmt: skip
        for i in range(m - 1):
            d, t, nz = _segment(guarded[i, 1], guarded[i + 1, 1], lo, hi)
            store(link_distance, link_normal, link_penalty, link_gradient, row, i,
                  d, 0.0, nz, rho)  # fmt: skip
            link_t[row, i] = t
