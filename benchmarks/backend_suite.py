"""Wall time of one backend over every bundled scene and a bench suite: where a backend stalls.

Usage::

    python benchmarks/backend_suite.py BACKEND [--seed 1] [--count 24] [--set key=value ...]

Plans each scene once (after one warm-up run that compiles the step) and prints the total, the
five slowest scenes with their refused backend calls, and the largest per-call time in the
solver. ``--set`` overrides a setting of a direct adapter (``--set max_iter=10000``) to compare
settings in one process: ratios between runs of this script on a quiet machine are meaningful,
absolute times are not.
"""

from __future__ import annotations

import argparse
import ast
import time
from pathlib import Path

import checkout  # noqa: F401  (this checkout's dvqp, not an installed one)
import numpy as np

import solvers
from dvqp import load_scene, plan
from dvqp.bench.generate import generate_scenes
from dvqp.scenes import loads

SCENES = Path(__file__).resolve().parent.parent / "scenes"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("backend")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--count", type=int, default=24)
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    args = parser.parse_args()
    overrides = {k: ast.literal_eval(v) for k, v in (s.split("=", 1) for s in args.set)}
    if overrides:  # the registry makes backends with their class's defaults: override those
        cls = type(solvers.make_backend(args.backend))
        cls.default_settings = {**cls.default_settings, **overrides}
    scenes = [load_scene(p) for p in sorted(SCENES.glob("*.toml"))]
    scenes += [loads(s.text, f"{s.name}.toml") for s in generate_scenes(args.seed, args.count)]
    plan(scenes[0], args.backend)  # compiled (or loaded) once
    took = []
    for scene in scenes:
        started = time.perf_counter()
        traj = plan(scene, args.backend)
        seconds = time.perf_counter() - started
        worst = float(np.max(traj.solver_time, initial=0.0))
        took.append((seconds, scene.name, traj.refused or "none refused", worst))
    total = sum(t[0] for t in took)
    print(f"{args.backend} {overrides or ''}: {len(scenes)} scenes in {total:.1f} s")
    for seconds, name, refused, worst in sorted(took, reverse=True)[:5]:
        print(f"  {name:<22} {seconds:7.2f} s  slowest step's solver {worst:.3f} s  ({refused})")


if __name__ == "__main__":
    main()
