"""The cost of obstacles with a height: a step's median with each obstacle a solid against the
same scene's with every obstacle unbounded (a wall to the sky), on pinv and DAQP.

Usage::

    python benchmarks/heights_benchmark.py [--backends pinv,daqp] [--repeat 5]

Three pairs of scenes, each pair one file edited two ways:

- ``support-band``: the bundled scene as it is (a 25 mm band, a 12 mm pad) against the same
  file without its ``height`` keys (which breaks the margin from the start and gives way on
  189 steps: a different motion, as a user meets it);
- ``paper/stubs``: ``paper-two-inlets`` with its inlets 3 cm stubs (the body passes over the
  lower one) against the walls of the paper;
- ``paper/1 m``: the same inlets 1 m tall against the walls: the same motion to the last
  digit, so the ratio is the cost of the solid's code path alone (3-D distances, the links'
  lowest points, the straight solids of the objective).

Each repeat runs every (pair, variant, backend) once, in a fresh process and a rotated order,
so that drift of the machine's speed falls on all alike. Ratios compare medians of this run
(the first step of each run, which pays set-ups, left out); the target is <= 1.2.
"""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

import numpy as np
from checkout import ROOT  # before dvqp: this checkout's, not an installed one
from step_benchmark import isolated

import dvqp

SCENES = Path(ROOT) / "scenes"


def _heights(text: str, height: float | None) -> str:
    """Every ``[[obstacles]]`` table of ``text`` given ``height`` (None: none at all)."""
    text = re.sub(r"(?m)^height = .*\n", "", text)
    if height is None:
        return text
    return text.replace("[[obstacles]]", "[[obstacles]]\nheight = " + repr(height))


def variants() -> dict[str, tuple[str, str]]:
    """``pair -> (text with heights, the same without)``."""
    band = (SCENES / "support-band.toml").read_text(encoding="utf-8")
    paper = (SCENES / "paper-two-inlets.toml").read_text(encoding="utf-8")
    return {
        "support-band": (band, _heights(band, None)),
        "paper/stubs": (_heights(paper, 0.03), paper),
        "paper/1 m": (_heights(paper, 1.0), paper),
    }


def measure(text: str, name: str, backend: str) -> tuple[np.ndarray, bool]:
    """Step times (s) of one run, the first left out, and whether the run is safe to send."""
    scene = dvqp.scenes.loads(text, f"{name}.toml")
    traj = dvqp.plan(scene, backend)
    try:
        dvqp.check_run(scene, traj)
        ok = True
    except dvqp.DvqpError:
        ok = False
    return traj.step_time[1:], ok


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--backends", default="pinv,daqp")
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args(argv)
    backends = args.backends.split(",")
    pairs = variants()
    runs = [(p, v, b) for p in pairs for v in (0, 1) for b in backends]
    times: dict[tuple[str, int, str], list[np.ndarray]] = {r: [] for r in runs}
    safe: dict[tuple[str, int, str], bool] = {}
    for r in range(args.repeat):
        for pair, variant, backend in runs[r % len(runs) :] + runs[: r % len(runs)]:
            found, ok = isolated(measure, pairs[pair][variant], pair, backend)
            times[pair, variant, backend].append(found)
            safe[pair, variant, backend] = ok
        print(f"repeat {r + 1}/{args.repeat} done", file=sys.stderr)
    print(f"step medians, us ({args.repeat} repeats; ratio = with heights / unbounded)")
    header = f"{'scene':<14} {'backend':<8} {'heights':>8} {'unbounded':>9} {'ratio':>6}  safe"
    print(header)
    print("-" * len(header))
    worst = 0.0
    for pair in pairs:
        for backend in backends:
            bounded = float(np.median(np.concatenate(times[pair, 0, backend]))) * 1e6
            walls = float(np.median(np.concatenate(times[pair, 1, backend]))) * 1e6
            ratio = bounded / walls
            worst = max(worst, ratio)
            ok = "/".join("yes" if safe[pair, v, backend] else "no" for v in (0, 1))
            print(f"{pair:<14} {backend:<8} {bounded:8.1f} {walls:9.1f} {ratio:6.2f}  {ok}")
    print(f"largest ratio {worst:.2f} (target <= 1.2)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
