"""Pieces every shape's compiled proximity kernel shares: l wrapping and the buffers' layout.

A shape class's kernel (:meth:`~dvqp.geometry.shapes.shape.Shape.kernel`) is a numba function
called as ``function(guarded, period, <the class's packed constants>, indices, *outputs)``:
``guarded`` is the plan's (k+1, 3) ``[l, z, h]`` of the guarded points (read), ``period`` the
pipe's ``2πR`` (m), ``indices`` (J,) int64 the rows of this class's shapes in the set, and
``outputs`` the nine arrays of :class:`~dvqp.compiled.plan.ProximityBuffers` in the order of
:func:`proximity_outputs`, written in place.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from numba import njit

from dvqp.geometry.shapes.shape import Array

if TYPE_CHECKING:
    from dvqp.compiled.plan import ProximityBuffers


def proximity_outputs(buffers: ProximityBuffers) -> tuple[Array, ...]:
    """The buffers' arrays in the kernels' argument order: point distance, normal, penalty,
    penalty gradient, then link distance, normal, penalty, penalty gradient and t."""
    return tuple(getattr(buffers, name) for name in _OUTPUTS)


_OUTPUTS = (
    "point_distance", "point_normal", "point_penalty", "point_penalty_gradient",
    "link_distance", "link_normal", "link_penalty", "link_penalty_gradient", "link_t",
)  # fmt: skip


@njit(cache=True)
def wrap(dl: float, period: float) -> float:
    """An arc-length difference wrapped into ``[−period/2, period/2)``, m (as
    :func:`~dvqp.geometry.shapes.shape.wrap_l`)."""
    half = 0.5 * period
    return (dl + half) % period - half


@njit(cache=True)
def store(
    distance: Array, normal: Array, penalty: Array, gradient: Array, row: int, i: int,
    d: float, nl: float, nz: float, rho: float,
) -> None:  # fmt: skip
    """Write signed distance ``d`` (m) and normal ``(nl, nz)`` at ``[row, i]``, with the
    penalty ``e = d (d + 2ρ)`` (m²) and ``∇e = 2 (d + ρ) ∇d`` (m) of
    :meth:`~dvqp.geometry.shapes.shape.Shape.penalty`."""
    distance[row, i] = d
    normal[row, i, 0] = nl
    normal[row, i, 1] = nz
    penalty[row, i] = d * (d + 2.0 * rho)
    scale = 2.0 * (d + rho)
    gradient[row, i, 0] = scale * nl
    gradient[row, i, 1] = scale * nz
