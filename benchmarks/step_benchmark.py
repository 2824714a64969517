"""Per-step timing of every backend on one scene: medians, p95 and ratios, in one run.

Usage::

    python benchmarks/step_benchmark.py [SCENE] [--backends pinv,daqp,...] [--repeat 5]

Each repeat runs the whole scene once per backend, in a rotated order so that drift of the
machine's speed falls on every backend alike. A "full step" is what ``simulate`` times:
kinematics + objective + (QP assembly + solve + check, or the pseudoinverse); "solve" is the
resolver alone. Ratios compare medians measured in this same run. Timing is noisy on a shared
machine: compare ratios, not absolute numbers across runs.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

import dvqp
import solvers
from dvqp.resolution.registry import default_resolvers

ROOT = Path(__file__).resolve().parent.parent


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scene", nargs="?", default=str(ROOT / "scenes" / "paper-two-inlets.toml"))
    parser.add_argument("--backends", help="comma-separated (default: pinv, every plain name and "
                        "the qpsolvers: path of each direct adapter)")  # fmt: skip
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args(argv)
    scene = dvqp.load_scene(args.scene)
    if args.backends:
        backends = args.backends.split(",")
    else:
        plain = default_resolvers()
        direct = [f"qpsolvers:{b}" for b in ("osqp", "clarabel", "daqp", "proxqp") if b in plain]
        backends = [*plain, *(b for b in direct if b in solvers.available_backends())]
    step: dict[str, list[np.ndarray]] = {b: [] for b in backends}
    solve: dict[str, list[np.ndarray]] = {b: [] for b in backends}
    failures = dict.fromkeys(backends, 0)
    for r in range(args.repeat):
        order = backends[r % len(backends) :] + backends[: r % len(backends)]
        for name in order:
            traj = dvqp.plan(scene, name)
            step[name].append(traj.step_time[1:])  # the first step pays the solver's setup
            solve[name].append(traj.solve_time[1:])
            failures[name] += int(np.sum(~traj.success))
        print(f"repeat {r + 1}/{args.repeat} done", file=sys.stderr)
    n_steps = len(step[backends[0]][0]) + 1
    print(f"scene {scene.name}: {n_steps} steps x {args.repeat} repeats, "
          f"{len(scene.obstacles)} obstacles")  # fmt: skip
    med = {b: float(np.median(np.concatenate(step[b]))) * 1e6 for b in backends}
    base = med.get("pinv")
    header = (f"{'backend':<20} {'step med µs':>11} {'step p95 µs':>11} {'/pinv':>6} "
              f"{'solve med µs':>12} {'qpsolvers/direct':>16} {'failed':>6}")  # fmt: skip
    print(header)
    print("-" * len(header))
    for b in backends:
        all_steps = np.concatenate(step[b]) * 1e6
        solve_med = float(np.median(np.concatenate(solve[b]))) * 1e6
        ratio = f"{med[b] / base:6.2f}" if base else "     -"
        generic = f"qpsolvers:{b}"
        vs = f"{med[generic] / med[b]:16.2f}" if generic in med else " " * 16
        print(f"{b:<20} {med[b]:11.1f} {np.percentile(all_steps, 95):11.1f} {ratio} "
              f"{solve_med:12.1f} {vs} {failures[b]:6d}")  # fmt: skip
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
