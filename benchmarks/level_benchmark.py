"""The cost of strict task priorities: a step with 1, 2 and 3 levels of the same scene.

Usage::

    python benchmarks/level_benchmark.py [SCENE] [--backend daqp] [--repeat 5]

On one scene (default ``scenes/reach-priorities.toml``, whose reach along the weld runs out
near its end) it plans the same motion with the tool as one task (1 level: the paper's step),
with the tool's height and heading above its place along the weld (2 levels: the scene's own
``[[tasks]]``), and with a posture task below those (3 levels: ``PostureTask(priority=3)``,
which is never met exactly, so every step solves its levels one after the other). Each run is
timed by its per-step ``step_time`` (the whole verified step, µs); the runs of one repeat go one
after the other, and each ratio is that repeat's median over the 1-level run's median of the
same repeat (this machine's speed drifts from second to second). Printed: the median step over
every repeat, the median of the ratios and their spread, and the median of the steps where the
lowest level gave way (``relaxed``) and of those where every level was met (``optimal``).
"""

from __future__ import annotations

import argparse
import dataclasses

import numpy as np
from checkout import ROOT  # before dvqp: this checkout's, not an installed one

import dvqp


def variants(scene: dvqp.Scene) -> dict[str, tuple[dvqp.Scene, tuple[dvqp.Task, ...]]]:
    """The scene at 1, 2 and 3 levels, and the tasks each run adds to it."""
    one = dataclasses.replace(scene, tasks=())
    two = scene if len(scene.spec().levels) == 2 else one
    return {
        "1 level (tool)": (one, ()),
        "2 levels (h, alpha / l, z)": (two, ()),
        "3 levels (+ posture)": (two, (dvqp.PostureTask(priority=3),)),
    }


def times(scene: dvqp.Scene, backend: str) -> dict[str, dvqp.Trajectory]:
    """One run of each variant."""
    return {
        name: dvqp.plan(variant, backend, tasks=tasks)
        for name, (variant, tasks) in variants(scene).items()
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scene", nargs="?", default=str(ROOT / "scenes" / "reach-priorities.toml"))
    parser.add_argument("--backend", default="daqp")
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args(argv)
    scene = dvqp.load_scene(args.scene)
    times(scene, args.backend)  # compile or load everything first
    steps: dict[str, list[np.ndarray]] = {}
    ratios: dict[str, list[float]] = {}
    kinds: dict[str, dict[str, list[np.ndarray]]] = {}
    for _ in range(args.repeat):
        runs = times(scene, args.backend)
        base = float(np.median(next(iter(runs.values())).step_time))
        for name, traj in runs.items():
            steps.setdefault(name, []).append(traj.step_time)
            ratios.setdefault(name, []).append(float(np.median(traj.step_time)) / base)
            moving = slice(0, traj.brake_start if traj.brake_start >= 0 else traj.n_steps)
            status = traj.status[moving]
            for kind in ("optimal", "relaxed"):
                kinds.setdefault(name, {}).setdefault(kind, []).append(
                    traj.step_time[moving][status == kind]
                )
    print(f"scene {scene.name}, backend {args.backend}, {args.repeat} repeats")
    header = f"{'levels':<28} {'median us':>9} {'x 1 level':>9} {'spread':>11}"
    print(header + f" {'optimal us':>10} {'relaxed us':>10}")
    print("-" * (len(header) + 22))
    for name, found in steps.items():
        median = float(np.median(np.concatenate(found))) * 1e6
        r = ratios[name]
        by_kind = []
        for kind in ("optimal", "relaxed"):
            joined = np.concatenate(kinds[name][kind])
            by_kind.append(f"{np.median(joined) * 1e6:10.1f}" if joined.size else f"{'-':>10}")
        spread = f"{min(r):.2f}-{max(r):.2f}"
        print(f"{name:<28} {median:9.1f} {np.median(r):9.2f} {spread:>11} {' '.join(by_kind)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
