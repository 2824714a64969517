"""Dense convex quadratic program with shape and value checks."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from .exceptions import ProblemShapeError

#: Largest tolerated asymmetry of ``P``, relative to ``1 + max|P|``.
SYMMETRY_TOLERANCE = 1e-9


def _as_array(name: str, value: object) -> np.ndarray:
    try:
        array = np.array(value, dtype=np.float64, order="C", copy=True)
    except (TypeError, ValueError) as exc:
        raise ProblemShapeError(f"{name}: cannot convert to a float64 array ({exc})") from exc
    return array


def _check_shape(name: str, array: np.ndarray, expected: tuple[int | str, ...]) -> None:
    ok = array.ndim == len(expected) and all(
        isinstance(want, str) or got == want
        for got, want in zip(array.shape, expected, strict=False)
    )
    if not ok:
        shown = f"({', '.join(map(str, expected))}{',' if len(expected) == 1 else ''})"
        raise ProblemShapeError(f"{name}: expected shape {shown}, got {array.shape}")


def _require(name: str, ok: np.ndarray, what: str) -> None:
    """Raise naming ``name`` and the first index where ``ok`` is False."""
    if not ok.all():
        index = tuple(int(i) for i in np.argwhere(~ok)[0])
        where = index[0] if len(index) == 1 else index
        raise ProblemShapeError(f"{name}: {what} (first at index {where})")


@dataclass(frozen=True, eq=False)
class Problem:
    r"""Convex QP :math:`\min \tfrac12 x^T P x + q^T x` s.t. equalities, inequalities, bounds.

    .. math::

        A x = b, \qquad G x \le h, \qquad lb \le x \le ub.

    On construction every array is copied to a read-only float64 C-contiguous array
    and validated; any inconsistency raises :class:`~solvers.ProblemShapeError`
    whose message starts with the field name. :meth:`trusted` skips both, for a
    caller that owns preallocated arrays and rewrites them in place between solves.

    Parameters
    ----------
    P : array_like, shape (n, n)
        Symmetric (checked) and positive semi-definite (not checked: with an
        indefinite ``P`` a solver may return a KKT point that passes the check).
    q : array_like, shape (n,)
        Cost vector (finite).
    A : array_like, shape (m, n), optional
        Equality matrix (finite). A zero-row ``A`` is treated as absent.
    b : array_like, shape (m,), optional
        Equality right-hand side (finite). Given if and only if ``A`` is.
    G : array_like, shape (p, n), optional
        Inequality matrix (finite). A zero-row ``G`` is treated as absent.
    h : array_like, shape (p,), optional
        Inequality right-hand side; ``+inf`` marks a row that can never be
        active, NaN and ``-inf`` are rejected. Given if and only if ``G`` is.
    lb, ub : array_like, shape (n,), optional
        Bounds on ``x``; may hold ``-inf`` / ``+inf`` respectively, never NaN,
        and ``lb <= ub`` elementwise.
    """

    P: np.ndarray
    q: np.ndarray
    A: np.ndarray | None = None
    b: np.ndarray | None = None
    G: np.ndarray | None = None
    h: np.ndarray | None = None
    lb: np.ndarray | None = None
    ub: np.ndarray | None = None

    if TYPE_CHECKING:  # the generated __init__ accepts anything array-like

        def __init__(
            self,
            P: npt.ArrayLike,
            q: npt.ArrayLike,
            A: npt.ArrayLike | None = None,
            b: npt.ArrayLike | None = None,
            G: npt.ArrayLike | None = None,
            h: npt.ArrayLike | None = None,
            lb: npt.ArrayLike | None = None,
            ub: npt.ArrayLike | None = None,
        ) -> None: ...

    def __post_init__(self) -> None:
        arrays = {
            name: None if value is None else _as_array(name, value)
            for name, value in (
                ("P", self.P),
                ("q", self.q),
                ("A", self.A),
                ("b", self.b),
                ("G", self.G),
                ("h", self.h),
                ("lb", self.lb),
                ("ub", self.ub),
            )
        }
        q = arrays["q"]
        if q is None:
            raise ProblemShapeError("q: expected shape (n,), got None")
        if q.ndim != 1:
            _check_shape("q", q, ("n",))
        n = q.shape[0]
        P = arrays["P"]
        if P is None:
            raise ProblemShapeError(f"P: expected shape ({n}, {n}), got None")
        if P.shape != (n, n):
            _check_shape("P", P, (n, n))
        for mat, vec, rows in (("A", "b", "m"), ("G", "h", "p")):
            M, v = arrays[mat], arrays[vec]
            if M is not None and (M.ndim != 2 or M.shape[1] != n):
                _check_shape(mat, M, (rows, n))
            if v is not None and (v.ndim != 1 or (M is not None and v.shape[0] != M.shape[0])):
                _check_shape(vec, v, (rows if M is None else M.shape[0],))
            if (M is None or M.shape[0] == 0) and (v is None or v.shape[0] == 0):
                arrays[mat] = arrays[vec] = None
            elif M is None or v is None:
                raise ProblemShapeError(
                    f"{vec if v is None else mat}: must be given together with "
                    f"{mat if v is None else vec}"
                )
        for name in ("lb", "ub"):
            bound = arrays[name]
            if bound is not None and bound.shape != (n,):
                _check_shape(name, bound, (n,))
        self._check_values(arrays)
        for name, array in arrays.items():
            if array is not None:
                array.flags.writeable = False
            object.__setattr__(self, name, array)

    def _check_values(self, arrays: dict[str, np.ndarray | None]) -> None:
        # Fast paths first (one reduction per array; a sum is finite only if every element
        # is), exact element-wise checks only to confirm and locate a problem.
        for name in ("P", "q", "A", "b", "G"):
            array = arrays[name]
            if array is not None and not math.isfinite(float(array.sum())):
                _require(name, np.isfinite(array), "must be finite")
        P = arrays["P"]
        assert P is not None
        if not (P == P.T).all():
            asym = float(np.abs(P - P.T).max(initial=0.0))
            if asym > SYMMETRY_TOLERANCE * (1.0 + float(np.abs(P).max(initial=0.0))):
                raise ProblemShapeError(f"P: must be symmetric, max |P - P^T| = {asym:.1e}")
        h, lb, ub = arrays["h"], arrays["lb"], arrays["ub"]
        for name, v, bad, what in (
            ("h", h, -np.inf, "must not be NaN or -inf"),
            ("lb", lb, np.inf, "must not be NaN or +inf"),
            ("ub", ub, -np.inf, "must not be NaN or -inf"),
        ):
            if v is not None and not math.isfinite(float(v.sum())):
                _require(name, ~np.isnan(v) & (v != bad), what)
        if lb is not None and ub is not None and (ub < lb).any():
            _require("lb", lb <= ub, "must be <= ub")

    @classmethod
    def trusted(
        cls,
        P: np.ndarray,
        q: np.ndarray,
        A: np.ndarray | None = None,
        b: np.ndarray | None = None,
        G: np.ndarray | None = None,
        h: np.ndarray | None = None,
        lb: np.ndarray | None = None,
        ub: np.ndarray | None = None,
    ) -> Problem:
        """Wrap arrays the caller built and vouches for, without validation or copies.

        For a fixed-structure workspace that owns its data, e.g. a control loop
        that overwrites preallocated arrays in place between solves: build one
        trusted problem over those arrays once, mutate the arrays, and pass the
        same problem to ``backend.solve`` every step. The problem keeps the very
        arrays given (writable, shared with the caller), so every solution's
        ``problem`` shows the data of the latest mutation, not of its own solve.

        The caller owns what the constructor would check: every array float64
        and C-contiguous, shapes consistent (``P`` (n, n), ``q``/``lb``/``ub``
        (n,), ``A`` (m, n) with ``b`` (m,), ``G`` (p, n) with ``h`` (p,)), ``P``
        symmetric, no NaN, ``h`` and ``ub`` never ``-inf``, ``lb`` never
        ``+inf``, ``lb <= ub``. ``h = +inf`` rows (with any ``G`` row, zeros
        included) are allowed, as in the regular constructor. Violations are not
        detected here; they give wrong residuals, solver errors, or failed
        solutions. As in the constructor, a zero-row ``A`` or ``G`` counts as
        absent.

        Parameters
        ----------
        P, q, A, b, G, h, lb, ub : ndarray
            As in :class:`Problem`, but already float64 C-contiguous arrays.

        Returns
        -------
        Problem
            Sharing the given arrays.
        """
        problem = object.__new__(cls)
        if A is not None and A.shape[0] == 0:
            A = b = None
        if G is not None and G.shape[0] == 0:
            G = h = None
        problem.__dict__.update(P=P, q=q, A=A, b=b, G=G, h=h, lb=lb, ub=ub)
        return problem

    @property
    def n(self) -> int:
        """Number of variables."""
        return int(self.q.shape[0])

    @property
    def n_eq(self) -> int:
        """Number of equality rows (0 when ``A`` is absent)."""
        return 0 if self.A is None else int(self.A.shape[0])

    @property
    def n_in(self) -> int:
        """Number of inequality rows (0 when ``G`` is absent)."""
        return 0 if self.G is None else int(self.G.shape[0])

    @property
    def has_bounds(self) -> bool:
        """Whether ``lb`` or ``ub`` is given (entries may still be infinite)."""
        return self.lb is not None or self.ub is not None
