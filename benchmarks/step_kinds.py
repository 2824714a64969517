"""The cost of the steps that are not the common one, as ratios to it, in one process.

Usage::

    python benchmarks/step_kinds.py [SCENE] [--backend daqp] [--repeat 3]

On one scene and backend it times (medians of ``step_time`` over the run's steps, µs):
the plain run; the same run with a limit of your own written in NumPy
(``docs/examples/probe_floor.py``'s ``ProbeFloor``, a floor far below the probe so that it
only adds its row) and with its compiled twin (``CompiledProbeFloor``); large steps (the scene
at 10× its ``dt``: steps moving a joint more than ``JOINT_STRIDE`` are checked at interior
points), and the steps split because they broke a limit (rare: at 0.3 and 0.5 s on the
paper scene; they cost their substeps, each a large step, against unsplit steps of that dt);
and the
JOG console's step (``ConsoleSession.step``, the scene's JOG command held). Each kind is run
``--repeat`` times, in a rotated order; ratios are to the plain run's median.
"""

from __future__ import annotations

import argparse
import dataclasses
import importlib.util
import sys
import time

import numpy as np
from checkout import ROOT  # before dvqp: this checkout's, not an installed one

import dvqp
from dvqp.console import ConsoleSession
from dvqp.step import JOINT_STRIDE

SPLIT_DT = (0.3, 0.5)
"""s: steps of the paper scene at which a few steps break a limit and are split."""


def example(name: str):  # type: ignore[no-untyped-def]
    """A module of ``docs/examples``, imported under its own name (numba's cache of its
    kernels refers to it by that name)."""
    spec = importlib.util.spec_from_file_location(name, ROOT / "docs" / "examples" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)  # type: ignore[arg-type]
    sys.modules[spec.name] = module  # type: ignore[union-attr]
    spec.loader.exec_module(module)  # type: ignore[union-attr]
    return module


def kinds(scene: dvqp.Scene, backend: str) -> dict[str, np.ndarray]:
    """Per-step times (s) of every kind of step, one run each."""
    floor = example("probe_floor")
    out = {"plain": dvqp.plan(scene, backend).step_time}
    out["user limit, NumPy"] = dvqp.plan(scene, backend, limits=[floor.ProbeFloor(-1.0)]).step_time
    compiled = floor.CompiledProbeFloor(-1.0)
    out["user limit, kernel"] = dvqp.plan(scene, backend, limits=[compiled]).step_time
    coarse = dvqp.plan(dataclasses.replace(scene, dt=10 * scene.dt), backend)
    motion = np.abs(np.diff(coarse.q, axis=0)).max(axis=1)
    out["large step (10 dt)"] = coarse.step_time[(motion > JOINT_STRIDE) & (coarse.substeps == 1)]
    for dt in SPLIT_DT:  # steps so large that a limit breaks: some are split
        long = dvqp.plan(dataclasses.replace(scene, dt=dt), backend)
        out[f"unsplit, dt {dt} s"] = long.step_time[long.substeps == 1]
        out[f"split, dt {dt} s"] = long.step_time[long.substeps > 1]
        out[f"split per substep, {dt} s"] = (long.step_time / long.substeps)[long.substeps > 1]
    session = ConsoleSession(scene, backend)
    session.jog(scene.jog[0].velocity)
    times = []
    for _ in range(500):
        started = time.perf_counter()
        session.step()
        times.append(time.perf_counter() - started)
    out["console step"] = np.array(times)
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scene", nargs="?", default=str(ROOT / "scenes" / "paper-two-inlets.toml"))
    parser.add_argument("--backend", default="daqp")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args(argv)
    scene = dvqp.load_scene(args.scene)
    kinds(scene, args.backend)  # compile or load everything first
    found: dict[str, list[np.ndarray]] = {}
    for _ in range(args.repeat):
        for name, times in kinds(scene, args.backend).items():
            found.setdefault(name, []).append(times)
    medians = {
        k: float(np.median(np.concatenate(v))) * 1e6 if sum(map(len, v)) else np.nan
        for k, v in found.items()
    }
    counts = {k: sum(map(len, v)) for k, v in found.items()}
    print(f"scene {scene.name}, backend {args.backend}, {args.repeat} repeats")
    print(f"{'kind':<22} {'steps':>7} {'median us':>10} {'x plain':>8}")
    for name, value in medians.items():
        print(f"{name:<22} {counts[name]:7d} {value:10.1f} {value / medians['plain']:8.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
