"""Both timings of every bundled path scene side by side: fixed (the paper's: the task relaxes
where the limits bind) and scaled (the QP slows the tool along the path there).

Usage::

    python benchmarks/timing_modes.py [SCENE ...] [--backends daqp,osqp,clarabel]

Prints a Markdown table (docs/comparison.md shows it): steps slowed and relaxed, the path's
nominal duration and how long the run took to follow it, the tool's worst distance from the
path over all samples and over the samples whose step fixed timing relaxed, and whether the run
is safe to send (``dvqp.check_run``).
"""

from __future__ import annotations

import argparse
import sys

import numpy as np
from checkout import ROOT  # before dvqp: this checkout's, not an installed one

import dvqp
from dvqp.motion.schedule import path_deviation
from dvqp.run.comparison import summarize
from dvqp.run.planning import scene_commands


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenes", nargs="*")
    parser.add_argument("--backends", default="daqp,osqp,clarabel")
    args = parser.parse_args(argv)
    files = args.scenes or sorted(str(p) for p in (ROOT / "scenes").glob("*.toml"))
    print(
        "| scene | backend | timing | ok | slowed | relaxed | nominal s | took s "
        "| worst dev mm | dev where fixed relaxed mm |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|")
    for file in files:
        scene = dvqp.load_scene(file)
        if scene.path is None:
            continue
        reference = scene_commands(scene).reference
        for backend in args.backends.split(","):
            runs = {t: dvqp.plan(scene, backend, timing=t) for t in ("fixed", "scaled")}
            relaxed = np.flatnonzero(runs["fixed"].status == "relaxed") + 1  # samples reached
            for timing, traj in runs.items():
                row = summarize(scene, traj)
                deviation = path_deviation(reference, traj.tool)
                # where fixed timing relaxed: the same part of the path (by nominal time)
                where = np.isin(np.round(traj.path_time / scene.dt).astype(int), relaxed)
                worst = f"{deviation[where].max() * 1e3:.3g}" if where.any() else "-"
                print(
                    f"| {scene.name} | {backend} | {timing} | {'yes' if row['success'] else 'NO'}"
                    f" | {row['slowed']} | {row['relaxed']} | {row['nominal_duration']:.2f}"
                    f" | {row['path_duration']:.2f} | {row['max_deviation'] * 1e3:.3g} | {worst} |"
                )
            sys.stdout.flush()
    return 0


if __name__ == "__main__":
    sys.exit(main())
