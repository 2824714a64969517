"""The broad phase's boxes: lower bounds of clearances that cost a few operations.

An obstacle's box (:attr:`~dvqp.geometry.measure.ShapeArrays.box`) against a part's
(:func:`box_bound`) or against the whole chain's (:func:`chain_box`, :func:`obstacle_bound`):
their distance never exceeds the true clearance, so a part or an obstacle farther than the
influence distance needs no exact measurement (:func:`~dvqp.geometry.measure.measure_chain`).
"""

from __future__ import annotations

import math

from dvqp.kinematics.developed_view import wrap_period
from solvers.jit import njit


@njit(inline="always")
def _gap(lo, hi, a, b):  # type: ignore[no-untyped-def]
    """How far the interval ``[min(a, b), max(a, b)]`` is from ``[lo, hi]`` (m), signed by
    its side (0: they overlap)."""
    if min(a, b) > hi:
        return min(a, b) - hi
    if max(a, b) < lo:
        return max(a, b) - lo
    return 0.0


@njit
def box_bound(shapes, j, al, az, bl, bz):  # type: ignore[no-untyped-def]
    """``(b, n_l, n_z)``: the distance (m) from the box of the segment ``a → b`` (a point if
    ``a = b``) to obstacle j's box, a lower bound of its clearance, and its direction."""
    box = shapes.box[j]
    la = wrap_period(al - shapes.data[j, 0], shapes.period)
    gl = _gap(box[0], box[1], la, la + wrap_period(bl - al, shapes.period))
    gz = _gap(box[2], box[3], az, bz)
    b = math.hypot(gl, gz)
    return (b, gl / b, gz / b) if b > 0.0 else (0.0, 0.0, 0.0)


@njit
def chain_box(chain, ends, period):  # type: ignore[no-untyped-def]
    """``(l0, l_lo, l_hi, z_lo, z_hi)``: a box (m) holding the points ``chain`` and the DV
    segments ``ends`` between them, l from the first point's ``l0`` (unwrapped from it)."""
    l0, lo, hi, zlo, zhi = chain[0, 0], 0.0, 0.0, chain[0, 1], chain[0, 1]
    for i in range(chain.shape[0]):
        u = wrap_period(chain[i, 0] - l0, period)
        lo, hi, zlo, zhi = min(lo, u), max(hi, u), min(zlo, chain[i, 1]), max(zhi, chain[i, 1])
    for i in range(ends.shape[0]):
        a, b = chain[ends[i, 0], 0], chain[ends[i, 1], 0]
        u = wrap_period(a - l0, period) + wrap_period(b - a, period)
        lo, hi = min(lo, u), max(hi, u)
    return l0, lo, hi, zlo, zhi


@njit(inline="always")
def obstacle_bound(shapes, j, l0, lo, hi, zlo, zhi):  # type: ignore[no-untyped-def]
    """The distance (m) from the chain's box (:func:`chain_box`) to obstacle j's box: a lower
    bound of every row's clearance to it (the obstacle taken at its nearest period)."""
    own, period = shapes.box[j], shapes.period
    gz = abs(_gap(own[2], own[3], zlo, zhi))
    if own[0] == -math.inf:
        return gz
    c = wrap_period(shapes.data[j, 0] - l0, period)
    gl = math.inf
    for k in range(-1, 2):
        gl = min(gl, abs(_gap(c + own[0], c + own[1], lo + k * period, hi + k * period)))
    return math.hypot(gl, gz)
