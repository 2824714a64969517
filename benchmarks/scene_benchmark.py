"""Per-step median of every bundled scene for pinv and DAQP, and its ratio to the paper scene.

Usage::

    python benchmarks/scene_benchmark.py [SCENE ...] [--backends pinv,daqp] [--repeat 5]

Without scene files it runs every ``scenes/*.toml`` and ``benchmarks/scenes/*.toml``. Each run
is a whole ``dvqp.plan`` of one scene with one backend; the first step, which pays set-ups, is
left out. The ratio is to ``paper-two-inlets`` (the paper's scene: two circles) with the same
backend, and it is taken in pairs: every run of a scene is bracketed by runs of the paper scene
just before and after it, and its ratio is to their mean. This machine's speed drifts by up to
half within seconds (the same code, the same process: paper-two-inlets' DAQP step at 29 µs,
then 42 µs a run later), so a ratio of medians taken minutes apart is noise; a bracketed
ratio sees the machine at the speed of its own neighbours. Each repeat runs every scene, in an
order rotated from the last one's, in one fresh process per backend (compiled code loaded from
the cache before the first timed run; a backend's side effects on a process reach no other
backend's). Printed per scene and backend: the median step (µs) over every run, and the median
over the repeats of the bracketed ratio, with its spread (least–largest) over the repeats.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
from checkout import ROOT  # before dvqp: this checkout's, not an installed one
from step_benchmark import isolated

PAPER = "paper-two-inlets"


def median_step(scene: object, backend: str) -> float:
    """The median wall time (s) of every step but the first of one run of ``scene``."""
    import dvqp

    traj = dvqp.plan(scene, backend)  # type: ignore[arg-type]
    return float(np.median(traj.step_time[1:]))


def bracketed(files: list[str], paper: str, backend: str) -> list[tuple[float, float]]:
    """Per scene file, ``(median step (s), its ratio to the mean of the paper scene's runs just
    before and after it)``, all in this process."""
    import dvqp

    scenes = [dvqp.load_scene(f) for f in files]
    reference = dvqp.load_scene(paper)
    median_step(reference, backend)  # loads the compiled code
    before, out = median_step(reference, backend), []
    for scene in scenes:
        step = median_step(scene, backend)
        after = median_step(reference, backend)
        out.append((step, step / (0.5 * (before + after))))
        before = after
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scenes", nargs="*")
    parser.add_argument("--backends", default="pinv,daqp")
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args(argv)
    files = args.scenes or [
        str(f)
        for f in sorted(
            [*(ROOT / "scenes").glob("*.toml"), *(ROOT / "benchmarks" / "scenes").glob("*.toml")]
        )
    ]
    names = [Path(f).stem for f in files]
    paper = str(ROOT / "scenes" / f"{PAPER}.toml")
    backends = args.backends.split(",")
    steps: dict[tuple[str, str], list[float]] = {}
    ratios: dict[tuple[str, str], list[float]] = {}
    for r in range(args.repeat):
        shift = r % len(files)
        order = files[shift:] + files[:shift]
        for b in backends:
            for f, (step, ratio) in zip(order, isolated(bracketed, order, paper, b), strict=True):
                steps.setdefault((Path(f).stem, b), []).append(step)
                ratios.setdefault((Path(f).stem, b), []).append(ratio)
        print(f"repeat {r + 1}/{args.repeat} done", file=sys.stderr)
    header = f"{'scene':<20}" + "".join(
        f" {b + ' us':>9} {'/paper':>6} {'spread':>11}" for b in backends
    )
    print(header)
    print("-" * len(header))
    for name in names:
        cells = ""
        for b in backends:
            ratio = ratios[name, b]
            cells += (
                f" {np.median(steps[name, b]) * 1e6:9.1f} {np.median(ratio):6.2f} "
                f"{min(ratio):5.2f}-{max(ratio):<5.2f}"
            )
        print(f"{name:<20}{cells}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
