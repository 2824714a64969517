"""Compiled (numba) proximity of the guarded points and links to circles.

The same arithmetic as :meth:`~dvqp.geometry.shapes.circle.Circle.batch_points` and
:meth:`~dvqp.geometry.shapes.circle.Circle.batch_segments`, one point or link at a time,
written straight into the plan's buffers (argument order: :mod:`.shape_kernels`).
"""

from __future__ import annotations

import math

from numba import njit

from dvqp.geometry.shapes.shape import Array
from dvqp.geometry.shapes.shape_kernels import wrap

_TINY = 1e-12
_MIN_LENGTH2 = 1e-18


@njit(cache=True)
def _store(
    distance: Array, normal: Array, penalty: Array, gradient: Array, row: int, i: int,
    sl: float, sz: float, radius: float,
) -> None:  # fmt: skip
    """From the offset ``s = S − p`` (m): ``‖s‖ − R``, ``−s/‖s‖`` (0 at the centre),
    ``‖s‖² − R²`` and ``−2 s``."""
    dist = math.sqrt(sl * sl + sz * sz)
    distance[row, i] = dist - radius
    if dist > _TINY:
        normal[row, i, 0] = -(sl / dist)
        normal[row, i, 1] = -(sz / dist)
    else:
        normal[row, i, 0] = 0.0
        normal[row, i, 1] = 0.0
    penalty[row, i] = dist**2 - radius**2
    gradient[row, i, 0] = -2.0 * sl
    gradient[row, i, 1] = -2.0 * sz


@njit(cache=True)
def circles(
    guarded: Array, period: float, centers: Array, radii: Array, indices: Array,
    point_distance: Array, point_normal: Array, point_penalty: Array, point_gradient: Array,
    link_distance: Array, link_normal: Array, link_penalty: Array, link_gradient: Array,
    link_t: Array,
) -> None:  # fmt: skip
    """Circles ``centers`` (J, 2) of ``radii`` (J,), m, against the k+1 points and k links of
    ``guarded`` (k+1, 3); shape j's results go to row ``indices[j]`` of the outputs."""
    m = guarded.shape[0]
    for j in range(indices.shape[0]):
        row = indices[j]
        cl, cz, radius = centers[j, 0], centers[j, 1], radii[j]
        for i in range(m):
            sl = wrap(cl - guarded[i, 0], period)
            sz = cz - guarded[i, 1]
            _store(point_distance, point_normal, point_penalty, point_gradient, row, i,
                   sl, sz, radius)  # fmt: skip
        for i in range(m - 1):
            gl = wrap(guarded[i + 1, 0] - guarded[i, 0], period)
            gz = guarded[i + 1, 1] - guarded[i, 1]
            length2 = max(gl * gl + gz * gz, _MIN_LENGTH2)  # a zero-length link gives t = 0
            sl = wrap(cl - guarded[i, 0], period)
            sz = cz - guarded[i, 1]
            t = min(max((sl * gl + sz * gz) / length2, 0.0), 1.0)
            _store(link_distance, link_normal, link_penalty, link_gradient, row, i,
                   sl - t * gl, sz - t * gz, radius)  # fmt: skip
            link_t[row, i] = t
