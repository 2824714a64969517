"""Per-solve overhead of the ``solvers`` layer on a fixed-structure QP, direct vs ``qpsolvers:``.

Usage::

    python benchmarks/solver_overhead.py [--steps 2000] [--backends daqp,osqp,...] [--seed 0]

The QP has dvqp's shape: n = 13 variables, 4 equality rows, 60 inequality rows of which 30
have ``h = +inf`` (15 of them with a zero ``G`` row), and bounds (one variable unbounded).
Its data live in preallocated arrays that every step overwrites in place (a drifting feasible
centre, drifting ``A``/``G``/``q``, ``P`` changed every ``--p-every`` steps, one row of ``h``
toggled between finite and ``+inf`` every 250 steps); one :meth:`solvers.Problem.trusted`
wraps them once and every step calls ``backend.solve(problem)`` on it.

Per backend the script prints the median over the steps (after a short warm-up) of:

- ``total``: the whole ``backend.solve`` call;
- ``solver``: the solver library's own calls (``Solution.solver_time``; set-up or update
  plus solve), ``n/a`` where the backend does not report it;
- ``check``: one extra :meth:`solvers.Solution.checked` call on the returned answer (the
  residual check that ``total`` contains);
- ``rest``: ``total - solver``, i.e. what the layer adds;

plus the number of solutions found, of cold retries, the largest distance of a found ``x``
to the first backend's, and for each direct adapter the ratio ``qpsolvers:NAME / NAME`` of
``total``.
The last lines time ``Problem(...)`` (validated copies, what a per-step build costs) against
``Problem.trusted``, and the public :func:`solvers.residuals` (the compiled kernel behind
``check``, plus its argument conversions). Timing is noisy on a shared machine: compare
ratios within one run.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable

import checkout  # noqa: F401  (this checkout's dvqp, not an installed one)
import numpy as np

import solvers
from solvers import Problem, Solution

N, M_EQ, P_IN, P_FINITE, P_STALE = 13, 4, 60, 30, 15
DIRECT = ("daqp", "osqp", "clarabel", "proxqp")


class Workspace:
    """Preallocated QP arrays and the drift that rewrites them in place each step."""

    def __init__(self, seed: int, p_every: int) -> None:
        rng = self.rng = np.random.default_rng(seed)
        self.p_every = p_every
        basis = rng.standard_normal((N, N))
        self.P0 = basis @ basis.T / N + 0.1 * np.eye(N)
        self.P = self.P0.copy()
        self.q0 = 2.0 * rng.standard_normal(N)
        self.q = self.q0.copy()
        self.A = rng.standard_normal((M_EQ, N))
        self.b = np.zeros(M_EQ)
        self.G = rng.standard_normal((P_IN, N))
        self.G[P_FINITE + P_STALE :] = 0.0  # inactive rows with a zero G row
        self.h = np.full(P_IN, np.inf)
        self.finite = np.arange(P_IN) < P_FINITE
        self.margin = 0.05 * rng.random(P_IN)
        self.margin[::5] = 0.0  # some rows active at the centre
        self.width = 0.2 + 0.3 * rng.random(N)
        self.lb, self.ub = np.zeros(N), np.zeros(N)
        self.center = 0.3 * rng.standard_normal(N)

    def problem(self) -> Problem:
        """One trusted problem over the arrays (a validated copy before ``trusted`` existed)."""
        if hasattr(Problem, "trusted"):
            return Problem.trusted(self.P, self.q, self.A, self.b, self.G, self.h, self.lb, self.ub)
        return self.validated()

    def validated(self) -> Problem:
        """A regular, validated ``Problem`` of the current data (copies everything)."""
        return Problem(self.P, self.q, self.A, self.b, self.G, self.h, self.lb, self.ub)

    def step(self, k: int) -> None:
        """Overwrite every array in place with the data of step ``k``."""
        rng = self.rng
        if self.p_every and k % self.p_every == 0:
            S = 0.02 * rng.standard_normal((N, N))
            np.add(self.P0, S @ S.T, out=self.P)
        if k % 250 == 249:  # a row enters or leaves the active region
            row = (k // 250) % P_FINITE
            self.finite[row] = not self.finite[row]
        self.center += 0.003 * rng.standard_normal(N)
        self.q += 0.01 * (self.q0 - self.q) + 0.02 * rng.standard_normal(N)
        self.A += 0.003 * rng.standard_normal(self.A.shape)
        self.G[:P_FINITE] += 0.003 * rng.standard_normal((P_FINITE, N))
        np.dot(self.A, self.center, out=self.b)
        np.dot(self.G, self.center, out=self.h)
        self.h += self.margin
        self.h[~self.finite] = np.inf
        np.subtract(self.center, self.width, out=self.lb)
        np.add(self.center, self.width, out=self.ub)
        self.lb[-1], self.ub[-1] = -np.inf, np.inf


def run(name: str, args: argparse.Namespace) -> dict[str, np.ndarray]:
    """Solve the drifting QP ``args.steps`` times with backend ``name``; per-step records."""
    ws = Workspace(args.seed, args.p_every)
    problem = ws.problem()
    backend = solvers.make_backend(name)
    warmup = 20
    keys = ("total", "solver", "check", "found", "retried")
    rows: dict[str, list[float]] = {key: [] for key in keys}
    xs = []
    trusted = hasattr(Problem, "trusted")
    for k in range(args.steps + warmup):
        ws.step(k)
        if not trusted:
            problem = ws.validated()
        started = time.perf_counter()
        sol = backend.solve(problem)
        total = time.perf_counter() - started
        started = time.perf_counter()
        Solution.checked(
            problem,
            sol.x,
            backend=name,
            tolerance=sol.tolerance,
            status=sol.status,
            y=sol.y,
            z=sol.z,
            z_box=sol.z_box,
        )
        check = time.perf_counter() - started
        if k < warmup:
            continue
        rows["total"].append(total)
        rows["solver"].append(getattr(sol, "solver_time", np.nan) or np.nan)
        rows["check"].append(check)
        rows["found"].append(sol.found)
        rows["retried"].append(sol.retried)
        xs.append(sol.x if sol.found else np.full(N, np.nan))
    records = {key: np.array(value, dtype=float) for key, value in rows.items()}
    records["x"] = np.array(xs)
    return records


def median_us(fn: Callable[[], object], repeat: int = 5000) -> float:
    """Median wall time of ``fn()`` in µs."""
    times = np.empty(repeat)
    for i in range(repeat):
        started = time.perf_counter()
        fn()
        times[i] = time.perf_counter() - started
    return float(np.median(times) * 1e6)


def extras(args: argparse.Namespace) -> None:
    """Problem construction (validated vs trusted) and the public residual computation."""
    ws = Workspace(args.seed, args.p_every)
    ws.step(0)
    print(f"Problem(...) validated copies: {median_us(ws.validated):7.1f} us")
    if hasattr(Problem, "trusted"):
        print(f"Problem.trusted(...):          {median_us(ws.problem):7.1f} us")
    problem = ws.problem()
    sol = solvers.make_backend("daqp").solve(problem)
    x, y, z, zb = sol.x, sol.y, sol.z, sol.z_box
    residuals_us = median_us(lambda: solvers.residuals(problem, x, y, z, zb))
    print(f"solvers.residuals(...):        {residuals_us:7.1f} us")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--steps", type=int, default=2000)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--p-every", type=int, default=100, help="steps between P changes")
    parser.add_argument("--backends", default=",".join(DIRECT), help="direct adapter names")
    args = parser.parse_args()
    installed = set(solvers.available_backends())
    names = [n for n in args.backends.split(",") if n in installed]
    names += [f"qpsolvers:{n}" for n in names if f"qpsolvers:{n}" in installed]
    print(
        f"n={N}, {M_EQ} equalities, {P_IN} inequalities ({P_IN - P_FINITE} with h=+inf), "
        f"bounds; {args.steps} steps, P changed every {args.p_every} steps; medians in us"
    )
    header = f"{'backend':20} {'total':>8} {'solver':>8} {'check':>7} {'rest':>8}"
    print(header + f" {'found':>6} {'retried':>7} {'max|dx|':>9} {'qps/direct':>10}")
    reference, totals = None, {}
    for name in names:
        rec = run(name, args)
        total, solver = np.median(rec["total"]) * 1e6, np.median(rec["solver"]) * 1e6
        totals[name] = total
        if reference is None:
            reference = rec["x"]
        dx = float(np.nanmax(np.abs(rec["x"] - reference)))
        direct = name.removeprefix("qpsolvers:")
        ratio = f"{total / totals[direct]:10.1f}" if name != direct else f"{'':10}"
        rest = np.median(rec["total"] - rec["solver"]) * 1e6
        solver_s, rest_s = ("n/a", "n/a") if np.isnan(solver) else (f"{solver:.1f}", f"{rest:.1f}")
        print(
            f"{name:20} {total:8.1f} {solver_s:>8} {np.median(rec['check']) * 1e6:7.1f} "
            f"{rest_s:>8} {int(rec['found'].sum()):6d} {int(rec['retried'].sum()):7d} "
            f"{dx:9.1e} {ratio}"
        )
    extras(args)


if __name__ == "__main__":
    main()
