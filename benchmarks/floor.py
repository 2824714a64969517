"""dvqp's step beside its floor, Pinocchio's kinematics plus DAQP alone, stage by stage.

Usage::

    python benchmarks/floor.py [--repeat 5] [--scenes NAME,...] [--no-scenes]

(It measures this checkout's ``dvqp``, whatever is installed: ``benchmarks/checkout.py``.)

Everything is measured in this one process (compiled code loaded from the cache before the
first timed run), medians in µs:

- **The floor** on the paper scene (``scenes/paper-two-inlets.toml``): Pinocchio's
  ``computeJointJacobians`` and ``updateFramePlacements`` of the same model at every
  configuration of the DAQP run, and DAQP's own ``daqp.solve`` (called from Python, cold, the
  settings dvqp gives it) of the very QPs the run hands it, as ``dvqp export-qps`` writes them
  (:func:`dvqp.run.qp_export.applying`: only the rows that apply), summed over a step's calls.
- **dvqp's step**, the whole step of ``dvqp.plan`` (``Trajectory.step_time``), DAQP and the
  baseline (``pinv``), and its stages: kinematics (the compiled kinematics kernel alone),
  obstacles (the rest of the measure stage: every shape's distances, the link pairs, and the
  real links), objective, dampers (their distances), QP assembly (:func:`dvqp.step.stages.
  prepare`: the task rows, cost, bounds and damper rows; the baseline's includes its whole
  eq. 18), solve (the time inside DAQP's calls, ``solver_time``), the backend layer (the rest
  of ``solve_time``, the resolution's time without the evaluation of the state reached: the
  schedule's command, the row dropping, the data copy, the residual check of the answer),
  the exact verification (the conclusion without a sample) and recording (what the sample
  adds); "rest" is the step less those: the run's compiled loop (:mod:`dvqp.motion.follow`:
  the step's record and count) and the Python of the steps it hands over (refused, split).
  The stages are timed on the run's own states, one compiled call at a time, less the time of
  a call that runs no stage (about 0.3 µs); the step, solve and layer are the run's own
  timers, read inside the loop.
- **Per bundled scene**, pinv's and DAQP's median step and its ratio to the paper scene's
  (bracketed: the mean of the paper scene's runs just before and after it, this machine's
  speed drifting; median over the repeats), and, within each DAQP run, the median of its
  ``slowed`` and of its ``relaxed`` steps against its strict (``optimal``) ones, and the
  same of those that start a streak (the step before was strict: its warm strict attempt is
  made and refused before the fallback is solved) and of those within one.

Timing is noisy on a shared machine: compare the ratios, taken within one run.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
from checkout import ROOT  # before dvqp: this checkout's, not an installed one
from scene_benchmark import bracketed

import dvqp
import solvers
from dvqp.kinematics.model import kinematics
from dvqp.motion import follow
from dvqp.motion.recorder import TrajectoryRecorder
from dvqp.resolution.registry import make_resolver
from dvqp.run.planning import backend_settings
from dvqp.run.qp_export import applying
from dvqp.step import Stepper, stages
from dvqp.workspace import as_struct
from solvers.daqp_ import DaqpBackend

PAPER = ROOT / "scenes" / "paper-two-inlets.toml"
STAGES = (
    "kinematics",
    "obstacles",
    "objective",
    "dampers",
    "QP assembly",
    "solve",
    "backend layer",
    "verification",
    "recording",
)


def timed(call: Callable[[], object], repeat: int = 3) -> float:
    """The least of ``repeat`` wall times (s) of ``call()``."""
    best = np.inf
    for _ in range(repeat):
        started = time.perf_counter()
        call()
        best = min(best, time.perf_counter() - started)
    return best


def pinocchio_floor(scene: dvqp.Scene, qs: np.ndarray) -> np.ndarray:
    """Per configuration, Pinocchio's joint Jacobians and frame placements (s)."""
    import pinocchio as pin

    model = scene.robot.model
    data = model.createData()

    def both(q: np.ndarray) -> None:
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)

    return np.array([timed(lambda q=q: both(q)) for q in qs])


class Calls:
    """The backend calls of a run, per step, as DAQP's own arguments."""

    def __init__(self) -> None:
        self.steps: dict[int, list[tuple[np.ndarray, ...]]] = {}

    def __call__(self, step: int, kind: str, problem: solvers.Problem, solution: object) -> None:
        p, _ = applying(problem)
        n = p.n
        G = np.zeros((0, n)) if p.G is None else p.G
        A = np.zeros((0, n)) if p.A is None else p.A
        h, b = (np.zeros(0) if v is None else v for v in (p.h, p.b))
        lb = np.full(n, -np.inf) if p.lb is None else p.lb
        ub = np.full(n, np.inf) if p.ub is None else p.ub
        upper = np.concatenate([ub, h, b])
        lower = np.concatenate([lb, np.full(h.shape[0], -np.inf), b])
        sense = np.zeros(upper.shape[0], dtype=np.intc)
        sense[n + h.shape[0] :] = 5
        args = (p.P.copy(), p.q.copy(), np.vstack([G, A]), upper, lower, sense)
        self.steps.setdefault(step, []).append(args)


def daqp_floor(calls: Calls) -> np.ndarray:
    """Per step with backend calls, DAQP's own solve of them, cold, summed (s)."""
    import daqp

    settings = DaqpBackend.default_settings
    return np.array(
        [
            sum(timed(lambda a=a: daqp.solve(*a, **settings)) for a in problems)
            for problems in calls.steps.values()
        ]
    )


def stage_times(scene: dvqp.Scene, backend: str, traj: dvqp.Trajectory) -> dict[str, float]:
    """Median of each compiled stage (s) over the run's states, on a stepper of its own."""
    resolver = make_resolver(backend, scene.spec(), backend_settings(scene, backend))
    robot = scene.robot
    record = TrajectoryRecorder(traj.n_steps, robot.n, robot.n_points, robot.has_rail, 1)
    stepper = Stepper(
        robot, scene.pipe_radius, resolver, scene.q0, scene.dt, scene.obstacles, record.arrays
    )
    stepper.start(scene.q0)
    a, s, dt = stepper.arrays, stepper.struct, scene.dt
    model, state = as_struct(a.model), as_struct(a.state)
    command = np.zeros(4)
    found: dict[str, list[float]] = {k: [] for k in STAGES}
    evaluate = stages.evaluate
    OBJECTIVE, DAMPERS, CONCLUDE = stages.OBJECTIVE, stages.DAMPERS, stages.CONCLUDE
    prepare = stages.prepare_baseline if a.pinv.baseline else stages.prepare
    nothing = CONCLUDE + 1  # a stage past the last: the call alone
    for k in range(traj.n_steps):
        stepper.observe(traj.qdot[k - 1] if k else np.zeros(scene.robot.n), dt)
        stepper.load(traj.q[k])
        call = timed(lambda: evaluate(s, False, nothing, nothing))
        kin = timed(lambda: kinematics(model, scene.pipe_radius, state)) - call
        measure = timed(lambda: evaluate(s, False, stages.MEASURE, stages.MEASURE)) - call
        found["kinematics"].append(kin)
        links = timed(lambda: evaluate(s, False, stages.LINKS, stages.LINKS)) - call
        found["obstacles"].append(measure - kin + links)
        found["objective"].append(timed(lambda: evaluate(s, False, OBJECTIVE, OBJECTIVE)) - call)
        found["dampers"].append(timed(lambda: evaluate(s, False, DAMPERS, DAMPERS)) - call)
        stepper.record_at[0] = -1
        verify = timed(lambda: evaluate(s, False, CONCLUDE, CONCLUDE)) - call
        found["verification"].append(verify)
        stepper.record_at[0] = k
        found["recording"].append(
            timed(lambda: evaluate(s, False, CONCLUDE, CONCLUDE)) - call - verify
        )
        stepper.record_at[0] = -1
        stepper.prepare(command, dt)  # the command and dt written
        found["QP assembly"].append(timed(lambda: prepare(s, stages.ROWS, stages.CLOSE)) - call)
    return {k: float(np.median(v)) for k, v in found.items() if v}


def without_loop(scene: dvqp.Scene, backend: str, repeat: int) -> float:
    """The median step (s) of runs whose loop is neither cached nor compiled (a run that
    compiled its step: :data:`dvqp.motion.follow.COMPILE`), every step from Python."""
    policy, ready = follow.COMPILE, follow.ready
    follow.COMPILE, follow.ready = "never", lambda kernel, args: False
    try:
        runs = [dvqp.plan(scene, backend) for _ in range(repeat)]
    finally:
        follow.COMPILE, follow.ready = policy, ready
    return float(np.median(np.concatenate([r.step_time[1:] for r in runs])))


def paper_rows(repeat: int) -> dict[str, dict[str, float]]:
    """The paper scene's floor and each backend's step and stages (medians, s)."""
    scene = dvqp.load_scene(str(PAPER))
    out: dict[str, dict[str, float]] = {}
    for backend in ("daqp", "pinv"):
        dvqp.plan(scene, backend)  # loads every compiled function
        runs = [dvqp.plan(scene, backend) for _ in range(repeat)]
        step = np.concatenate([r.step_time[1:] for r in runs])
        solve = np.concatenate([r.solve_time[1:] for r in runs])
        solver = np.concatenate([r.solver_time[1:] for r in runs])
        row = stage_times(scene, backend, runs[0])
        row["step"] = float(np.median(step))
        row["no loop"] = without_loop(scene, backend, repeat)
        if backend == "daqp":
            row["solve"] = float(np.median(solver))
            row["backend layer"] = float(np.median(solve - solver)) - row["QP assembly"]
        else:
            row["solve"] = row["backend layer"] = 0.0  # eq. 18 is part of its QP assembly
        out[backend] = row
    calls = Calls()
    traj = dvqp.plan(scene, "daqp", watch=calls)
    pin_floor = np.concatenate([pinocchio_floor(scene, traj.q) for _ in range(repeat)])
    qp_floor = np.concatenate([daqp_floor(calls) for _ in range(repeat)])
    out["floor"] = {"pinocchio": float(np.median(pin_floor)), "daqp": float(np.median(qp_floor))}
    return out


def print_paper(rows: dict[str, dict[str, float]]) -> None:
    """The paper scene's table: stages, floor, ratios."""
    floor = rows["floor"]
    total = floor["pinocchio"] + floor["daqp"]
    print(f"paper scene ({PAPER.name}), medians in us")
    print(f"floor: pinocchio kinematics {floor['pinocchio'] * 1e6:6.2f}")
    print(f"       daqp.solve of the run's QPs {floor['daqp'] * 1e6:6.2f}")
    print(f"       floor {total * 1e6:6.2f}")
    header = f"{'stage':<16} {'daqp us':>8} {'/floor':>7} {'pinv us':>8} {'/floor':>7}"
    print(header)
    print("-" * len(header))
    for name in (*STAGES, "rest", "step"):
        cells = ""
        for b in ("daqp", "pinv"):
            r = rows[b]
            value = r["step"] - sum(r[k] for k in STAGES) if name == "rest" else r[name]
            cells += f" {value * 1e6:8.2f} {value / total:7.2f}"
        print(f"{name:<16}{cells}")
    print(
        f"daqp step {rows['daqp']['step'] / total:.2f}x the floor (target <= 2), "
        f"pinv step {rows['pinv']['step'] / total:.2f}x (target <= 1.5)"
    )
    print(
        "without the loop (a run that compiled its step): "
        + ", ".join(
            f"{b} {rows[b]['no loop'] * 1e6:.2f} us ({rows[b]['no loop'] / rows[b]['step']:.2f}x)"
            for b in ("daqp", "pinv")
        )
    )


def kinds(files: list[str], repeat: int) -> dict[str, tuple[float, ...]]:
    """Per scene file, the median of the DAQP runs' slowed and of their relaxed steps over
    that of their strict ones (``repeat`` runs; NaN: none), then the same of those that start
    a streak (the step before was strict) and of those within one, and how many of each a
    run has: ``(slowed, relaxed, start, within, n_slowed, n_relaxed, n_start, n_within)``."""
    out = {}
    for f in files:
        scene = dvqp.load_scene(f)
        runs = [dvqp.plan(scene, "daqp") for _ in range(repeat)]
        status = np.concatenate([np.asarray(t.status)[1:] for t in runs])
        before = np.concatenate([np.asarray(t.status)[:-1] for t in runs])
        times = np.concatenate([t.step_time[1:] for t in runs])
        strict = np.median(times[status == "optimal"])
        fallen = (status == "slowed") | (status == "relaxed")
        start = fallen & (before == "optimal")
        ratios, counts = [], []
        for chosen in (status == "slowed", status == "relaxed", start, fallen & ~start):
            ratios.append(np.median(times[chosen]) / strict if chosen.any() else np.nan)
            counts.append(int(chosen.sum()) // repeat)
        out[Path(f).stem] = (*ratios, *counts)
    return out


def print_scenes(files: list[str], repeat: int) -> None:
    """Per scene: pinv and DAQP steps against the paper scene's; slowed, relaxed vs strict."""
    got: dict[tuple[str, str], list[tuple[float, float]]] = {}
    for r in range(repeat):
        order = files[r % len(files) :] + files[: r % len(files)]
        for b in ("pinv", "daqp"):
            for f, value in zip(order, bracketed(order, str(PAPER), b), strict=True):
                got.setdefault((Path(f).stem, b), []).append(value)
    found = kinds(files, repeat)
    header = (
        f"{'scene':<20} {'pinv us':>8} {'/paper':>6} {'daqp us':>8} {'/paper':>6} "
        f"{'slowed':>13} {'relaxed':>13} {'start':>13} {'within':>13}"
    )
    print(header)
    print("-" * len(header))
    for f in files:
        name = Path(f).stem
        cells = ""
        for b in ("pinv", "daqp"):
            steps, ratios = zip(*got[name, b], strict=True)
            cells += f" {np.median(steps) * 1e6:8.1f} {np.median(ratios):6.2f}"
        values = found[name]
        for ratio, count in zip(values[:4], values[4:], strict=True):
            cells += f" {ratio:6.2f} ({count:4d})" if count else f" {'-':>13}"
        print(f"{name:<20}{cells}")
    print("slowed, relaxed: their median step / the run's strict median (count); target <= 1.5")
    print(
        "start, within: the same of the slowed or relaxed steps that start a streak (the step "
        "before was strict:\n  its strict warm attempt refused, then the fallback solved) and "
        "of those within one"
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--scenes", help="comma-separated scene names (default: every bundled)")
    parser.add_argument("--no-scenes", action="store_true", help="the paper scene only")
    args = parser.parse_args(argv)
    print_paper(paper_rows(args.repeat))
    if args.no_scenes:
        return 0
    names = args.scenes.split(",") if args.scenes else None
    files = [
        str(f) for f in sorted((ROOT / "scenes").glob("*.toml")) if names is None or f.stem in names
    ]
    print()
    print_scenes(files, args.repeat)
    return 0


if __name__ == "__main__":
    sys.exit(main())
