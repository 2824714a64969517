"""How many DAQP iterations a refused strict problem costs, cold against warm.

Usage::

    python benchmarks/warm_refusals.py [SCENE]

Plans a scene (default ``scenes/weld-rush.toml``) with DAQP, keeps each step's strict problem
(a watcher of the backend calls), then solves them again in order, each twice: cold
(``daqp.solve``, from an empty working set, as dvqp's streak steps are solved after a
refusal) and warm (one ``daqp.Model`` updated from step to step, its working set kept through
refusals, which dvqp does not do: a warm refusal would need a certificate to be trusted). It
prints how many problems each refuses, whether they agree, and the iterations of the refused
ones: what a verified warm refusal would save a streak step. (dvqp now proves most of a
streak's refusals without any solve, from held multipliers: ``solvers.farkas``; this measures
the solves a refusal that is not proved costs.)
"""

from __future__ import annotations

import argparse
from typing import Any

import daqp
import numpy as np
from checkout import ROOT  # before dvqp: this checkout's, not an installed one

import dvqp

EQUALITY = 5
"""DAQP's sense of an equality row (active and immutable)."""


def stacked(problem: Any) -> tuple[np.ndarray, ...]:
    """A strict problem as DAQP takes it: ``H, f, M = [G; A], upper, lower, sense``."""
    n = problem.P.shape[0]
    G = problem.G if problem.G is not None else np.zeros((0, n))
    h = problem.h if problem.h is not None else np.zeros(0)
    A = problem.A if problem.A is not None else np.zeros((0, n))
    b = problem.b if problem.b is not None else np.zeros(0)
    upper = np.concatenate([problem.ub, h, b])
    lower = np.concatenate([problem.lb, np.full(h.size, -1e30), b])
    sense = np.zeros(upper.size, dtype=np.int32)
    sense[upper.size - b.size :] = EQUALITY
    arrays = (problem.P, problem.q, np.vstack([G, A]), upper, lower)
    return (*(np.ascontiguousarray(a, dtype=float).copy() for a in arrays), sense)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scene", nargs="?", default=str(ROOT / "scenes" / "weld-rush.toml"))
    args = parser.parse_args(argv)
    problems: list[tuple[np.ndarray, ...]] = []

    def keep(step: int, kind: str, problem: Any, solution: Any) -> None:
        if kind == "strict":
            problems.append(stacked(problem))

    dvqp.plan(dvqp.load_scene(args.scene), "daqp", watch=keep)
    if not problems:
        print("no strict problem")
        return 0
    buffers = [a.copy() for a in problems[0]]
    model = daqp.Model()
    model.setup(*buffers)
    rows = []
    for data in problems:
        for buffer, value in zip(buffers[:5], data[:5], strict=True):
            buffer[...] = value
        model.update(H=buffers[0], f=buffers[1], A=buffers[2], bupper=buffers[3], blower=buffers[4])
        _, _, warm_flag, warm = model.solve()
        _, _, cold_flag, cold = daqp.solve(*data)
        rows.append((warm_flag, warm["iterations"], cold_flag, cold["iterations"]))
    r = np.array(rows, dtype=float)
    cold_refused, warm_refused = r[:, 2] < 0, r[:, 0] < 0
    disagree = int((cold_refused != warm_refused).sum())
    print(
        f"strict problems {len(r)}: refused cold {int(cold_refused.sum())}, warm "
        f"{int(warm_refused.sum())}, the two disagree on {disagree}"
    )
    both = cold_refused & warm_refused
    if both.any():
        cold_its, warm_its = r[both, 3], r[both, 1]
        print(
            f"refused: iterations cold median {np.median(cold_its):.0f} "
            f"({cold_its.min():.0f}-{cold_its.max():.0f}), warm median {np.median(warm_its):.0f} "
            f"({warm_its.min():.0f}-{warm_its.max():.0f})"
        )
    accepted = ~cold_refused & ~warm_refused
    if accepted.any():
        print(
            f"accepted: iterations cold median {np.median(r[accepted, 3]):.0f}, warm median "
            f"{np.median(r[accepted, 1]):.0f}"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
