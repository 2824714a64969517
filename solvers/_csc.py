"""Fixed CSC sparsity patterns for dense data, so per-step updates are a gather."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp


@dataclass(frozen=True)
class CscPattern:
    """CSC structure of the ``True`` entries of a boolean mask.

    Attributes
    ----------
    shape : tuple of int
        ``(rows, cols)`` of the matrix.
    indptr : ndarray, shape (cols + 1,)
        CSC column pointers.
    indices : ndarray, shape (nnz,)
        CSC row indices, sorted within each column.
    take : ndarray, shape (nnz,)
        Flat C-order indices into a dense ``(rows, cols)`` array, in CSC data order.
    """

    shape: tuple[int, int]
    indptr: np.ndarray
    indices: np.ndarray
    take: np.ndarray

    @classmethod
    def from_mask(cls, mask: np.ndarray) -> CscPattern:
        """Pattern of ``mask`` (shape (rows, cols)); explicit zeros are kept."""
        rows, cols = mask.shape
        col_idx, row_idx = np.nonzero(mask.T)  # sorted by column, then row
        indptr = np.zeros(cols + 1, dtype=np.int64)
        np.cumsum(np.bincount(col_idx, minlength=cols), out=indptr[1:])
        return cls((rows, cols), indptr, row_idx.astype(np.int64), row_idx * cols + col_idx)

    @classmethod
    def upper_triangle(cls, n: int) -> CscPattern:
        """Full upper triangle of an ``(n, n)`` matrix (what OSQP/Clarabel read of P)."""
        return cls.from_mask(np.triu(np.ones((n, n), dtype=bool)))

    def data(self, dense: np.ndarray) -> np.ndarray:
        """CSC data array of ``dense`` (shape ``self.shape``, C-contiguous)."""
        return np.take(dense, self.take)

    def matrix(self, dense: np.ndarray) -> sp.csc_matrix:
        """Scipy CSC matrix with this pattern and the values of ``dense``."""
        return sp.csc_matrix((self.data(dense), self.indices, self.indptr), shape=self.shape)
