"""Per-step timing of every backend on one scene, pink's step as the peer: medians and ratios.

Usage::

    python benchmarks/step_benchmark.py [SCENE] [--backends pinv,daqp,...] [--repeat 5]

Each repeat runs the whole scene once per backend, in a rotated order so that drift of the
machine's speed falls on every backend alike, each run in a fresh process (a backend's side
effects on a process — HiGHS leaves later backends measurably slower — reach no other run).
A "full step" is what ``simulate`` times: kinematics, objective, the resolution, the exact
check of the integrated step and the recording (the compiled step).
"resolve" is the resolver alone (QP assembly + solve + residual check, or the
pseudoinverse), "solver" the time inside the QP backend's own calls (data update and solve),
"rest" the full step less the solver. The peer line is
pink's ``solve_ik`` (FrameTask on the tool frame, ConfigurationLimit, VelocityLimit, DAQP) on
the same Pinocchio model, integration included (``pip install 'dvqp[bench]'``; skipped without
it). "daqp/subclassed" is DAQP on the scene with every part a plain subclass of its built-in
class (the same compiled step: its ratio to daqp's should be about 1). Ratios compare medians
measured in this same run. Timing is noisy on a shared machine:
compare ratios, not absolute numbers across runs.
"""

from __future__ import annotations

import argparse
import multiprocessing
import sys
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np
from checkout import ROOT  # before dvqp: this checkout's, not an installed one

import dvqp
import solvers
from dvqp.resolution.registry import default_resolvers

FIELDS = ("step_time", "solve_time", "solver_time")


def pink_steps(scene: dvqp.Scene, steps: int) -> np.ndarray | None:
    """Wall time (s) of ``steps`` pink steps following the tool along z, or None without pink."""
    try:
        import pink
        from pink.limits import ConfigurationLimit, VelocityLimit
        from pink.tasks import FrameTask
    except ImportError:
        return None
    model = scene.robot.model.copy()
    model.lowerPositionLimit = np.where(np.isfinite(scene.robot.q_min), scene.robot.q_min, -10.0)
    model.upperPositionLimit = np.where(np.isfinite(scene.robot.q_max), scene.robot.q_max, 10.0)
    model.velocityLimit = scene.robot.qd_max.copy()
    config = pink.Configuration(model, model.createData(), scene.q0.copy())
    frame = scene.robot.tool_frame
    task = FrameTask(frame, position_cost=1.0, orientation_cost=1.0)
    target = config.get_transform_frame_to_world(frame).copy()
    limits = [ConfigurationLimit(model), VelocityLimit(model)]
    times = np.empty(steps)
    for k in range(steps):
        target.translation[2] += 0.05 * scene.dt  # 5 cm/s along the pipe axis
        task.set_target(target)
        started = time.perf_counter()
        v = pink.solve_ik(config, [task], scene.dt, solver="daqp", limits=limits)
        config.integrate_inplace(v, scene.dt)
        times[k] = time.perf_counter() - started
    return times


def measure(scene_file: str, name: str) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """One run of ``name``: per-step times (the first step, which pays set-ups, left out) and
    the reported iterations."""
    traj = dvqp.plan(dvqp.load_scene(scene_file), name)
    return {f: getattr(traj, f)[1:] for f in FIELDS}, traj.iterations[traj.iterations >= 0]


SUBCLASSED = "daqp/subclassed"
"""The DAQP run of the scene with every part a trivial subclass of its built-in class."""


def measure_subclassed(scene_file: str) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """:func:`measure` of DAQP on the scene with every part (task, terms, limits, shapes) a
    trivial subclass of its built-in class: the same compiled step, which should cost the
    same."""
    from tests.step.subclassing import subclassed_tool_task, swapped

    scene, _ = swapped(dvqp.load_scene(scene_file))
    with subclassed_tool_task():
        traj = dvqp.plan(scene, "daqp")
    return {f: getattr(traj, f)[1:] for f in FIELDS}, traj.iterations[traj.iterations >= 0]


def pink_steps_of(scene_file: str) -> np.ndarray | None:
    """:func:`pink_steps` for as many steps as the scene has."""
    scene = dvqp.load_scene(scene_file)
    return pink_steps(scene, dvqp.plan(scene, "pinv").n_steps)


def isolated(function, *args):  # type: ignore[no-untyped-def]
    """``function(*args)`` in a fresh process: a backend's side effects on the process (HiGHS
    leaves the next backends measurably slower in the same process) never reach another's
    measurement. Compiled code is loaded from the cache, outside the timed steps."""
    context = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(max_workers=1, mp_context=context) as pool:
        return pool.submit(function, *args).result()


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scene", nargs="?", default=str(ROOT / "scenes" / "paper-two-inlets.toml"))
    parser.add_argument(
        "--backends",
        help="comma-separated (default: pinv, every plain name and "
        "the qpsolvers: path of each direct adapter)",
    )
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args(argv)
    scene = dvqp.load_scene(args.scene)
    if args.backends:
        backends = args.backends.split(",")
    else:
        plain = default_resolvers()
        direct = [f"qpsolvers:{b}" for b in ("osqp", "clarabel", "daqp", "proxqp") if b in plain]
        backends = [*plain, *(b for b in direct if b in solvers.available_backends())]
    if "daqp" in backends:
        backends.insert(backends.index("daqp") + 1, SUBCLASSED)
    got: dict[str, dict[str, list[np.ndarray]]] = {b: {f: [] for f in FIELDS} for b in backends}
    iterations: dict[str, list[np.ndarray]] = {b: [] for b in backends}
    peer: list[np.ndarray] = []
    for r in range(args.repeat):
        order = backends[r % len(backends) :] + backends[: r % len(backends)]
        for name in order:
            if name == SUBCLASSED:
                fields, its = isolated(measure_subclassed, args.scene)
            else:
                fields, its = isolated(measure, args.scene, name)
            for f in FIELDS:
                got[name][f].append(fields[f])
            iterations[name].append(its)
        found = isolated(pink_steps_of, args.scene)
        if found is not None:
            peer.append(found[1:])
        print(f"repeat {r + 1}/{args.repeat} done", file=sys.stderr)
    report(scene, backends, got, iterations, peer, args.repeat)
    return 0


def report(scene, backends, got, iterations, peer, repeat) -> None:  # type: ignore[no-untyped-def]
    """Print the table: medians (µs) of the full step, resolver, solver and rest; ratios."""
    med = {
        b: {f: float(np.median(np.concatenate(got[b][f]))) * 1e6 for f in FIELDS} for b in backends
    }
    pink_med = float(np.median(np.concatenate(peer))) * 1e6 if peer else None
    base = med.get("pinv", {}).get("step_time")
    print(
        f"scene {scene.name}: {len(got[backends[0]]['step_time'][0]) + 1} steps x {repeat} "
        f"repeats, {len(scene.obstacles)} obstacles, {len(scene.limits)} limits"
    )
    header = (
        f"{'backend':<20} {'step us':>8} {'resolve':>8} {'solver':>7} {'rest':>7} "
        f"{'iters':>5} {'/pinv':>6} {'/pink':>6} {'qpsolvers/direct':>16}"
    )
    print(header)
    print("-" * len(header))
    for b in backends:
        m = med[b]
        its = np.concatenate(iterations[b]) if iterations[b] else np.zeros(0)
        it = f"{np.median(its):5.0f}" if its.size else "    -"
        ratio = f"{m['step_time'] / base:6.2f}" if base else "     -"
        vs_pink = f"{m['step_time'] / pink_med:6.2f}" if pink_med else "     -"
        generic = f"qpsolvers:{b}"
        vs = f"{med[generic]['step_time'] / m['step_time']:16.2f}" if generic in med else " " * 16
        rest = m["step_time"] - m["solver_time"]
        print(
            f"{b:<20} {m['step_time']:8.1f} {m['solve_time']:8.1f} {m['solver_time']:7.1f} "
            f"{rest:7.1f} {it} {ratio} {vs_pink} {vs}"
        )
    if SUBCLASSED in med and "daqp" in med:
        ratio = med[SUBCLASSED]["step_time"] / med["daqp"]["step_time"]
        print(f"{SUBCLASSED}: every part a plain subclass, {ratio:.2f}x daqp's step (<= 1.3)")
    if pink_med is not None:
        print(f"{'pink (peer)':<20} {pink_med:8.1f}")
    else:
        print("pink (peer)          not installed: pip install 'dvqp[bench]'")


if __name__ == "__main__":
    raise SystemExit(main())
