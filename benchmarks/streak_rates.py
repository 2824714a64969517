"""Would a slowed streak end if its steps skipped the strict problem?

Usage::

    python benchmarks/streak_rates.py [SCENE]

Plans a time-scaled scene (default ``scenes/weld-rush.toml``) with DAQP and, beside every
step whose strict problem was accepted after the run's first slowed step, solves that step's
time-scaled problem too (on a backend of its own, cold; the run itself is left as it was) and
prints the rates ``σ`` it gives. A step the strict problem takes at full speed has ``σ = 1``
only if the time-scaled problem also moves at full speed; ``σ < 1`` there means that solving
the time-scaled problem first in a streak would slow steps the strict task takes, and the
streak would never end.
"""

from __future__ import annotations

import argparse
from typing import Any

import numpy as np
from checkout import ROOT  # before dvqp: this checkout's, not an installed one

import dvqp
from dvqp.resolution.qp import QPSolver


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scene", nargs="?", default=str(ROOT / "scenes" / "weld-rush.toml"))
    args = parser.parse_args(argv)
    statuses: list[str] = []
    rates: list[float] = []
    solve = QPSolver.solve

    def beside(self: QPSolver, *a: Any, **k: Any) -> Any:
        answer = solve(self, *a, **k)
        statuses.append(answer.status)
        if answer.status == "optimal" and self.scaled is not None and self.feedforward.any():
            b, pacer = self.qp.b.copy(), self._pacer
            self._pacer = self.factory()
            solution, rate = self._slow_down()
            self.qp.b[:], self._pacer = b, pacer
            if solution.found:
                rates.append(rate)
        return answer

    QPSolver.solve = beside  # type: ignore[method-assign]
    try:  # a watcher keeps every solve in Python, through QPSolver.solve
        dvqp.plan(dvqp.load_scene(args.scene), "daqp", watch=lambda *_: None)
    finally:
        QPSolver.solve = solve  # type: ignore[method-assign]
    r = np.array(rates)
    print(f"steps {len(statuses)}, slowed {statuses.count('slowed')}, strict after the first")
    print(f"slowed step {len(r)}: the time-scaled problem's sigma there")
    if r.size:
        print(
            f"min {r.min():.6f}  median {np.median(r):.6f}  max {r.max():.6f}  "
            f"at full speed (sigma = 1): {int(np.sum(r >= 1.0))} of {r.size}"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
