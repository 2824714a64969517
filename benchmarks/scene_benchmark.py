"""Per-step median of every bundled scene for pinv and DAQP, and its ratio to the paper scene.

Usage::

    python benchmarks/scene_benchmark.py [SCENE ...] [--backends pinv,daqp] [--repeat 3]

Without scene files it runs every ``scenes/*.toml`` and ``benchmarks/scenes/*.toml``. Each run
is a whole ``dvqp.plan`` of one scene with one backend in a fresh process (compiled code loaded
from the cache, outside the timed steps); the first step, which pays set-ups, is left out. The
repeats go round every scene and backend in turn, so that drift of the machine's speed falls on
all alike. The ratio is to ``paper-two-inlets`` (the paper's scene: two circles) with the same
backend, measured in the same run: compare ratios, not absolute numbers across runs.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
from step_benchmark import isolated

ROOT = Path(__file__).resolve().parent.parent
PAPER = "paper-two-inlets"


def step_times(scene_file: str, backend: str) -> np.ndarray:
    """Wall time (s) of every step but the first of one run of ``scene_file`` with ``backend``."""
    import dvqp

    traj = dvqp.plan(dvqp.load_scene(scene_file), backend)
    return np.asarray(traj.step_time[1:])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scenes", nargs="*")
    parser.add_argument("--backends", default="pinv,daqp")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args(argv)
    files = args.scenes or sorted(
        [*(ROOT / "scenes").glob("*.toml"), *(ROOT / "benchmarks" / "scenes").glob("*.toml")]
    )
    names = [Path(f).stem for f in files]
    backends = args.backends.split(",")
    got: dict[tuple[str, str], list[np.ndarray]] = {}
    for r in range(args.repeat):
        for f, name in zip(files, names, strict=True):
            for b in backends:
                got.setdefault((name, b), []).append(isolated(step_times, str(f), b))
        print(f"repeat {r + 1}/{args.repeat} done", file=sys.stderr)
    med = {key: float(np.median(np.concatenate(v))) * 1e6 for key, v in got.items()}
    header = f"{'scene':<22}" + "".join(f" {b + ' us':>10} {'/paper':>7}" for b in backends)
    print(header)
    print("-" * len(header))
    for name in names:
        cells = ""
        for b in backends:
            paper = med.get((PAPER, b))
            ratio = f"{med[name, b] / paper:7.2f}" if paper else "      -"
            cells += f" {med[name, b]:10.1f} {ratio}"
        print(f"{name:<22}{cells}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
