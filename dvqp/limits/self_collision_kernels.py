"""Compiled (numba) self-collision geometry and rows, in place.

:func:`pair_distances_into` computes every non-adjacent link pair's closest points once per
state (the reference :func:`dvqp.limits.self_collision.pair_distances` calls it too, so both
paths agree bit for bit); :func:`self_rows` writes the damper rows from them. Shapes: P pairs,
the chain of k+1 points ``o`` (m), the frames' Jacobians ``(k+1, 6, n)``.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import NDArray

from dvqp.limits.damper_kernels import Params, damper_value

Array = NDArray[np.float64]
Index = NDArray[np.int64]


@njit(cache=True)
def pair_distances_into(
    o: Array, pi: Index, pj: Index, dist: Array, normal: Array, ss: Array, tt: Array
) -> None:
    """Distance ``dist`` (P,), unit normal ``c_i − c_j`` (P, 3), ``s`` and ``t`` (P,) of the
    link pairs ``(pi, pj)`` of the chain ``o``, written in place: segment ``o[pi] → o[pi+1]``
    against ``o[pj] → o[pj+1]``.

    Ericson's clamped closest points (*Real-Time Collision Detection*, 5.1.9), exact for
    parallel and degenerate segments too."""
    eps = 1e-18
    for m in range(pi.shape[0]):
        a, b, c, d = o[pi[m]], o[pi[m] + 1], o[pj[m]], o[pj[m] + 1]
        d1x, d1y, d1z = b[0] - a[0], b[1] - a[1], b[2] - a[2]
        d2x, d2y, d2z = d[0] - c[0], d[1] - c[1], d[2] - c[2]
        rx, ry, rz = a[0] - c[0], a[1] - c[1], a[2] - c[2]
        aa = d1x * d1x + d1y * d1y + d1z * d1z
        e = d2x * d2x + d2y * d2y + d2z * d2z
        f = d2x * rx + d2y * ry + d2z * rz
        if aa <= eps and e <= eps:
            s, t = 0.0, 0.0
        elif aa <= eps:
            s, t = 0.0, min(max(f / e, 0.0), 1.0)
        else:
            cc = d1x * rx + d1y * ry + d1z * rz
            if e <= eps:
                s, t = min(max(-cc / aa, 0.0), 1.0), 0.0
            else:
                bb = d1x * d2x + d1y * d2y + d1z * d2z
                denom = aa * e - bb * bb
                s = min(max((bb * f - cc * e) / denom, 0.0), 1.0) if denom > eps * aa * e else 0.0
                t = (bb * s + f) / e
                if t < 0.0:
                    s, t = min(max(-cc / aa, 0.0), 1.0), 0.0
                elif t > 1.0:
                    s, t = min(max((bb - cc) / aa, 0.0), 1.0), 1.0
        x = (a[0] + s * d1x) - (c[0] + t * d2x)
        y = (a[1] + s * d1y) - (c[1] + t * d2y)
        z = (a[2] + s * d1z) - (c[2] + t * d2z)
        dist[m] = np.sqrt(x * x + y * y + z * z)
        scale = max(dist[m], 1e-15)
        normal[m, 0], normal[m, 1], normal[m, 2] = x / scale, y / scale, z / scale
        ss[m], tt[m] = s, t


@njit(cache=True)
def self_rows(
    pi: Index, pj: Index, dist: Array, normal: Array, s: Array, t: Array,
    frame_jacobians: Array, reach: float, params: Params, dt: Array, G: Array, h: Array,
) -> None:  # fmt: skip
    """One damper row per pair, ``G = −nᵀ((1 − s) J_{a_i} + s J_{b_i} − (1 − t) J_{a_j} −
    t J_{b_j})``, for the pairs closer than ``reach = margin + influence`` (m); the others
    ``0 ≤ +inf``."""
    step = dt[0]
    for m in range(pi.shape[0]):
        if not dist[m] < reach:
            G[m, :] = 0.0
            h[m] = np.inf
            continue
        i, j, sm, tm = pi[m], pj[m], s[m], t[m]
        jac = frame_jacobians
        for c in range(G.shape[1]):
            grad = 0.0
            for x in range(3):
                moving = (1 - sm) * jac[i, x, c] + sm * jac[i + 1, x, c]
                moving = moving - (1 - tm) * jac[j, x, c] - tm * jac[j + 1, x, c]
                grad += normal[m, x] * moving
            G[m, c] = -grad
        h[m] = damper_value(dist[m], params[0], params[1], step, params[2], params[3])
