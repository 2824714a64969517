"""QP test cases with known solutions, shared by the tests in ``tests/solvers/``.

``kkt_case`` builds a strictly convex QP *backwards* from a chosen optimum and
chosen multipliers (package sign convention), so the exact solution and its
unique multipliers are known without any solver.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from solvers import Problem


@dataclass
class KktCase:
    """A problem with its exact solution and multipliers."""

    problem: Problem
    x: np.ndarray
    y: np.ndarray | None
    z: np.ndarray | None
    z_box: np.ndarray | None


def spd(rng: np.random.Generator, n: int, floor: float = 0.5) -> np.ndarray:
    """Random symmetric positive definite matrix, eigenvalues >= ``floor``."""
    M = rng.standard_normal((n, n))
    return M @ M.T / n + floor * np.eye(n)


def equality_case(rng: np.random.Generator, n: int = 6, m: int = 2) -> KktCase:
    """Equality-only QP solved in closed form from its KKT system."""
    P, q = spd(rng, n), rng.standard_normal(n)
    A, b = rng.standard_normal((m, n)), rng.standard_normal(m)
    kkt = np.block([[P, A.T], [A, np.zeros((m, m))]])
    sol = np.linalg.solve(kkt, np.concatenate([-q, b]))
    return KktCase(Problem(P, q, A=A, b=b), sol[:n], sol[n:], None, None)


def kkt_case(
    rng: np.random.Generator,
    n: int = 8,
    m: int = 2,
    p: int = 6,
    active: int = 2,
    infinite: bool = False,
) -> KktCase:
    """QP with ``active`` active inequalities, one active lower and one upper bound.

    With ``infinite=True`` some inactive ``h`` rows and bounds are infinite.
    """
    P = spd(rng, n)
    x = rng.uniform(-1.0, 1.0, n)
    A = rng.standard_normal((m, n))
    y = rng.standard_normal(m)
    G = rng.standard_normal((p, n))
    z = np.zeros(p)
    z[:active] = rng.uniform(0.5, 2.0, active)
    h = G @ x + np.where(z > 0, 0.0, rng.uniform(0.2, 1.0, p))
    lb, ub = x - rng.uniform(0.2, 1.0, n), x + rng.uniform(0.2, 1.0, n)
    z_box = np.zeros(n)
    lb[0], z_box[0] = x[0], -rng.uniform(0.5, 2.0)  # active lower bound
    ub[1], z_box[1] = x[1], rng.uniform(0.5, 2.0)  # active upper bound
    if infinite:
        h[-1] = np.inf
        lb[2], ub[3], lb[4], ub[4] = -np.inf, np.inf, -np.inf, np.inf
    q = -(P @ x + A.T @ y + G.T @ z + z_box)
    problem = Problem(P, q, A=A, b=A @ x, G=G, h=h, lb=lb, ub=ub)
    return KktCase(problem, x, y, z, z_box)


def random_walk(seed: int, steps: int = 50, n: int = 14, m: int = 4) -> list[Problem]:
    """Slowly changing feasible QPs; every 10th step adds or drops an inequality row."""
    rng = np.random.default_rng(seed)
    M = rng.standard_normal((n, n))
    q = rng.standard_normal(n)
    A = rng.standard_normal((m, n))
    center = 0.3 * rng.standard_normal(n)
    G = rng.standard_normal((10, n))
    margin = 0.05 * rng.random(10)
    width = 0.2 + 0.3 * rng.random(n)
    problems = []
    for step in range(steps):
        M += 0.02 * rng.standard_normal(M.shape)
        q += 0.05 * rng.standard_normal(n)
        A += 0.02 * rng.standard_normal(A.shape)
        G += 0.02 * rng.standard_normal(G.shape)
        center += 0.01 * rng.standard_normal(n)
        if step % 10 == 9:
            if step % 20 == 9:
                G, margin = np.vstack([G, rng.standard_normal(n)]), np.append(margin, 0.02)
            else:
                G, margin = G[:-2], margin[:-2]
        P = M @ M.T / n + 0.05 * np.eye(n)
        problems.append(
            Problem(P, q, A, A @ center, G, G @ center + margin, center - width, center + width)
        )
    return problems


def random_problem(rng: np.random.Generator, n: int = 14, m: int = 4, p: int = 12) -> Problem:
    """An unrelated feasible QP of the same structure as :func:`random_walk`."""
    P = spd(rng, n, floor=0.05)
    A, G = rng.standard_normal((m, n)), rng.standard_normal((p, n))
    center = 0.3 * rng.standard_normal(n)
    width = 0.2 + 0.3 * rng.random(n)
    return Problem(
        P,
        5.0 * rng.standard_normal(n),
        A,
        A @ center,
        G,
        G @ center + 0.05 * rng.random(p),
        center - width,
        center + width,
    )
