"""Small compiled helpers of the adapters' per-step update paths.

Each compiles (or loads numba's cache) at its first call, for its one declared signature
(:func:`solvers.jit.compiled_on_first_call`); the arrays it is given must be float64 and
C-contiguous, of the declared dimensions, or the call raises ``TypeError``.
"""

from __future__ import annotations

import numpy as np
from numba import types

from .jit import compiled_on_first_call, njit

_VEC_IN = types.Array(types.float64, 1, "C", readonly=True)
_MAT_IN = types.Array(types.float64, 2, "C", readonly=True)
_VEC_OUT = types.Array(types.float64, 1, "C")
_MAT_OUT = types.Array(types.float64, 2, "C")

#: Read-only placeholders for absent blocks in compiled calls.
EMPTY_VECTOR = np.zeros(0)
EMPTY_MATRIX = np.zeros((0, 0))
EMPTY_VECTOR.flags.writeable = EMPTY_MATRIX.flags.writeable = False


@compiled_on_first_call(types.boolean(_MAT_IN, _MAT_OUT))
def refresh(source: np.ndarray, kept: np.ndarray) -> bool:
    """Copy ``source`` into ``kept`` (same shape) if any entry differs; return whether it did.

    About 0.3 µs for a 13 x 13 matrix, where ``np.array_equal`` alone takes ~2 µs. A NaN
    entry always counts as a change.
    """
    rows, cols = source.shape
    changed = False
    for i in range(rows):
        for j in range(cols):
            if source[i, j] != kept[i, j]:
                kept[i, j] = source[i, j]  # element by element: no broadcasting to compile
                changed = True
    return changed


@njit
def stack_into(
    P: np.ndarray,
    q: np.ndarray,
    A: np.ndarray,
    b: np.ndarray,
    G: np.ndarray,
    h: np.ndarray,
    lb: np.ndarray,
    ub: np.ndarray,
    data: np.ndarray,
    n: int,
    p: int,
    m: int,
    ms: int,
) -> int:
    """Copy a problem into DAQP's stacked data; -1 (nothing written) if a size misfits.

    ``data`` holds, one after the other, ``H`` (n x n), ``f`` (n), ``M`` ((p + m) x n),
    ``upper`` and ``lower`` (``ms + p + m`` each); this writes ``f = q``,
    ``M = [G; A]``, ``upper = [ub, h, b]``, ``lower = [lb, (kept), b]``, where an
    ``lb`` or ``ub`` of size 0 (absent) leaves its part as it was, and copies ``P``
    into ``H`` only if an entry differs (a NaN always does).

    Returns
    -------
    int
        -1 on a size mismatch, else 1 if ``H`` was rewritten (``P`` changed), else 0.
    """
    rows = ms + p + m
    misfit = data.shape[0] != n * (n + 1 + p + m) + 2 * rows or (ms != 0 and ms != n)
    misfit |= P.shape[0] != n or P.shape[1] != n or q.shape[0] != n
    misfit |= G.shape[0] != p or h.shape[0] != p or (p > 0 and G.shape[1] != n)
    misfit |= A.shape[0] != m or b.shape[0] != m or (m > 0 and A.shape[1] != n)
    misfit |= (lb.shape[0] != 0 and lb.shape[0] != ms) or (ub.shape[0] != 0 and ub.shape[0] != ms)
    if misfit:
        return -1
    f, M = n * n, n * n + n  # offsets of f, M, upper, lower in data
    upper = M + (p + m) * n
    lower = upper + rows
    for j in range(n):
        data[f + j] = q[j]
    for i in range(p):
        for j in range(n):
            data[M + i * n + j] = G[i, j]
        data[upper + ms + i] = h[i]
    for i in range(m):
        for j in range(n):
            data[M + (p + i) * n + j] = A[i, j]
        data[upper + ms + p + i] = data[lower + ms + p + i] = b[i]
    for j in range(ms if lb.shape[0] else 0):
        data[lower + j] = lb[j]
    for j in range(ms if ub.shape[0] else 0):
        data[upper + j] = ub[j]
    changed = 0
    for j in range(n):
        for k in range(n):
            if P[j, k] != data[j * n + k]:
                changed = 1
                data[j * n + k] = P[j, k]
    return changed


@compiled_on_first_call(
    types.int64(*(_MAT_IN, _VEC_IN) * 3, _VEC_IN, _VEC_IN, _VEC_OUT, *(types.int64,) * 4)
)
def stack(
    P: np.ndarray,
    q: np.ndarray,
    A: np.ndarray,
    b: np.ndarray,
    G: np.ndarray,
    h: np.ndarray,
    lb: np.ndarray,
    ub: np.ndarray,
    data: np.ndarray,
    n: int,
    p: int,
    m: int,
    ms: int,
) -> int:
    """:func:`stack_into`, compiled for its one signature, called from Python."""
    return stack_into(P, q, A, b, G, h, lb, ub, data, n, p, m, ms)
