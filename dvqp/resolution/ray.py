r"""The strict task's least violation: a QP whose multipliers prove a strict problem infeasible.

Over ``x = [Q̇; s]`` (n joints, m task rows):

.. math::

    \min_{Q̇, s} \; \tfrac12 ε \|Q̇\|^2 + \tfrac12 \|s\|^2 \quad \text{s.t.} \quad
    A Q̇ − s = b, \; G Q̇ \le h, \; lb \le Q̇ \le ub,

the step's own constraints and bounds, its task rows with a slack each, and no cost of the
step's. Its stationarity in ``Q̇``, ``ε Q̇ + Aᵀy + Gᵀz + z_box = 0``, with ``y = s``, makes
``(y, z)`` all but a Farkas ray of the strict problem's constraints: where those admit no
``Q̇`` by a margin (``‖s‖²`` above about ``ε ‖Q̇‖ ‖ub − lb‖``),
:func:`solvers.farkas.refuted` proves the strict problem infeasible from them, exactly, on
the strict problem's own data. The relaxed problem's multipliers (:func:`~dvqp.resolution.
levels.relaxed_problem`) carry the step's cost gradient besides: they prove it only where the
slack's penalty outweighs that gradient (joint-limit, pipe-rack), not where the violation is
slight (fold).

A run's compiled loop (:mod:`dvqp.motion.follow`) solves it where a strict refusal was not
proved by the multipliers the strict backend held, and holds its multipliers there for the
strict problem's next restarts (:func:`solvers.daqp_c.hold_multipliers`): a streak's strict
problems are then refused without a solve while the same ray proves them.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

import solvers
from dvqp.workspace import QPBuffers

EPSILON = 1e-6
"""``ε``, the weight of ``½‖Q̇‖²`` (rad²/s² against the slack's task units²/s²): small, so that
the multipliers are nearly a ray; enough to make the problem strictly convex (DAQP factors
its Hessian)."""


def ray_problem(qp: QPBuffers) -> solvers.Problem:
    """The least-violation problem over the step's arrays ``qp`` (see the module docstring):
    its ``Q̇`` columns of ``A``, ``G``, ``lb``, ``ub`` and its ``ε I`` block filled by
    :func:`~dvqp.resolution.levels.load_columns` with :func:`ray_constants`; ``b`` and ``h``
    shared with ``qp``."""
    n, p, m = qp.cost.shape[0], qp.h.shape[0], qp.b.shape[0]
    P = np.zeros((n + m, n + m))
    P[n:, n:] = np.eye(m)
    A = np.zeros((m, n + m))
    A[:, n:] = -np.eye(m)
    inf = np.full(m, np.inf)
    return solvers.Problem.trusted(
        P,
        np.zeros(n + m),
        A,
        qp.b,
        np.zeros((p, n + m)) if p else None,
        qp.h if p else None,
        np.concatenate([qp.lb, -inf]),
        np.concatenate([qp.ub, inf]),
    )


def ray_constants(n: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """What :func:`~dvqp.resolution.levels.load_columns` copies into the ``Q̇`` block of
    :func:`ray_problem`'s ``P`` and ``q`` in place of the step's cost: ``ε I`` (n, n) and
    ``0`` (n,)."""
    return EPSILON * np.eye(n), np.zeros(n)
