"""Every QP of a run as a file of ``qpsolvers.Problem``'s own format, with dvqp's answer.

:func:`export_qps` plans a scene on a QP backend and writes one file per backend call of the
run (``qpsolvers.Problem.save``: an ``.npz`` of ``P, q, G, h, A, b, lb, ub``, the problem as
the backend got it less the inequality rows that do not apply, ``0 · x ≤ +inf``), the answer
dvqp accepted beside it (``answers/``), an index (``index.json``: scene, step, kind, the rows
kept, active rows, warm-start pair) and qpbenchmark's test set of the folder
(``dvqp_qps.py``). The folder appears whole or not at all. Layout and fields:
``docs/qp-export.md``.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import tempfile
from collections import Counter
from collections.abc import Callable
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

import solvers
from dvqp._versions import __version__
from dvqp.errors import LimitViolationError, OutputError, ParameterError, UnreachableTargetError
from dvqp.motion.trajectory import Trajectory
from dvqp.resolution.registry import PINV, check_name
from dvqp.run.planning import backend_settings, check_run, plan
from dvqp.scenes.scene import Scene

INDEX = "index.json"
"""The index file of an export."""
ANSWERS = "answers"
"""The sub-folder of the answers, one file per problem, of the same name."""
FORMAT = "dvqp export-qps 2"
"""The index's ``format``: how :func:`export_qps` knows a folder it may replace (2: only the
rows that apply, ``rows`` and ``fixed_inequalities``; 1 kept every row)."""
FORMATS = ("dvqp export-qps 1", FORMAT)
"""The formats of the exports :func:`export_qps` may replace."""
TEST_SET = "dvqp_qps.py"
"""qpbenchmark's test set of the export, copied into it (its class: ``DvqpQps``)."""
TEST_SET_SOURCE = Path(__file__).with_name("qpbenchmark_set") / TEST_SET

EMPTY = np.zeros(0)


class Exported(NamedTuple):
    """What :func:`export_qps` wrote: the ``folder``, the run's ``trajectory`` and the
    ``index`` (the contents of ``index.json``)."""

    folder: Path
    trajectory: Trajectory
    index: dict[str, Any]


def export_qps(
    scene: Scene,
    backend: str,
    folder: str | Path,
    *,
    options: dict[str, Any] | None = None,
    tier: str = "default",
    force: bool = False,
    progress: Callable[[int, int], None] | None = None,
    notice: Callable[[str], None] | None = None,
) -> Exported:
    """Plan ``scene`` on the QP ``backend`` and write each of its backend calls' problems into
    ``folder`` (``<scene>-<step>-<call>.npz``, the rows that apply), with the answers,
    ``index.json`` and qpbenchmark's test set (``dvqp_qps.py``).

    The files are written into a temporary folder beside ``folder``, renamed to it once all
    are written: an error or an interrupt leaves nothing. A failed run is exported too (its
    index's ``error`` says why :func:`~dvqp.run.planning.check_run` fails it).

    Parameters
    ----------
    scene, backend
        What to run; ``backend`` a QP backend's name (not ``"pinv"``: it solves no QP).
    folder
        The export's folder: new, empty, or (``force``) an earlier export, replaced.
    options
        Settings of the backend, over the scene's ``[solvers.<backend>]`` ones, over the
        settings ``tier``'s (:mod:`solvers.tiers`; the index's ``tier`` and ``settings``).
    progress, notice
        As :func:`~dvqp.run.planning.plan`'s.

    Raises
    ------
    BackendError
        Unknown backend, or a setting it does not take.
    ParameterError
        ``backend`` is ``pinv``; ``folder`` is a file, not empty (and not an earlier export
        with ``force``), or its parent is missing or not writable.
    OutputError
        The files could not be written (a full disk).
    """
    if check_name(backend) == PINV:
        raise ParameterError("backend", "pinv solves no QP: name a QP backend (see dvqp backends)")
    target = _target(Path(folder), force)
    work = _work_folder(target)
    try:
        calls = _Calls(work, re.sub(r"[^A-Za-z0-9._-]", "_", scene.name))
        traj = plan(
            scene,
            backend,
            progress=progress,
            notice=notice,
            options=options,
            watch=calls,
            tier=tier,
        )
        settings = backend_settings(scene, backend, options, tier)
        index = calls.finish(scene, traj, backend, tier, settings)
        shutil.copyfile(TEST_SET_SOURCE, work / TEST_SET)
        _put_in_place(work, target)
    except BaseException as exc:
        shutil.rmtree(work, ignore_errors=True)
        if isinstance(exc, OSError) and not isinstance(exc, OutputError):
            raise OutputError(folder, exc.strerror or str(exc), exc.errno) from exc
        raise
    return Exported(target, traj, index)


class _Calls:
    """The watcher of a run's backend calls: each problem saved at once into ``folder``, its
    answer and index entry kept (both need the step's status, known once the run is over)."""

    def __init__(self, folder: Path, stem: str) -> None:
        self.folder, self.stem = folder, stem
        self.entries: list[dict[str, Any]] = []
        self.answers: list[dict[str, np.ndarray]] = []
        self.per_step: Counter[int] = Counter()
        self.warm: dict[str, str | None] = {}
        self.tolerance: float | None = None
        """The residual check's absolute tolerance of the backend (None: no call)."""
        self.fixed_rows = 0
        """Rows of ``G`` in the run's fixed structure (every problem of a run has them)."""

    def __call__(
        self, step: int, kind: str, problem: solvers.Problem, solution: solvers.Solution
    ) -> None:
        import qpsolvers

        call = self.per_step[step]
        self.per_step[step] += 1
        name = f"{self.stem}-{step:05d}-{call}.npz"
        p, rows = applying(problem)
        qpsolvers.Problem(p.P, p.q, p.G, p.h, p.A, p.b, p.lb, p.ub).save(str(self.folder / name))
        found = bool(solution.found and solution.x is not None)
        self.tolerance = solution.tolerance
        z = None if solution.z is None else solution.z[rows]
        self.entries.append(
            {
                "file": name,
                "answer": f"{ANSWERS}/{name}",
                "solve": len(self.entries),
                "step": step,
                "call": call,
                "kind": kind,
                "variables": p.n,
                "equalities": p.n_eq,
                "inequalities": p.n_in,
                "rows": rows.tolist(),
                "found": found,
                "refusal": "" if found else solution.refusal,
                "solver_status": str(solution.status),
                "iterations": None if solution.iterations is None else int(solution.iterations),
                "retried": bool(solution.retried),
                "warm_start": self.warm.get(kind),
                **active_rows(p, solution.x if found else None, z, solution.z_box, self.tolerance),
            }
        )
        s = solution  # x and the multipliers (empty: absent, or the call refused)
        self.answers.append(
            {
                key: EMPTY if value is None or not found else np.array(value)
                for key, value in (("x", s.x), ("y", s.y), ("z", z), ("z_box", s.z_box))
            }
        )
        self.fixed_rows = problem.n_in
        self.warm[kind] = name if found else None  # a refused call resets its backend: cold

    def finish(
        self, scene: Scene, traj: Trajectory, backend: str, tier: str, settings: dict[str, Any]
    ) -> dict[str, Any]:
        """Write the answers and the index (the run over); return the index."""
        (self.folder / ANSWERS).mkdir()
        for entry, answer in zip(self.entries, self.answers, strict=True):
            entry["step_status"] = str(traj.status[entry["step"]])
            entry["substeps"] = int(traj.substeps[entry["step"]])
            np.savez(
                self.folder / entry["answer"],
                **answer,
                found=np.array(entry["found"]),
                kind=np.array(entry["kind"]),
                step_status=np.array(entry["step_status"]),
                solver_status=np.array(entry["solver_status"]),
            )
        try:
            check_run(scene, traj)
            error = ""
        except (UnreachableTargetError, LimitViolationError) as exc:
            error = str(exc)
        index = {
            "format": FORMAT,
            "dvqp": __version__,
            "scene": scene.name,
            "source": scene.source,
            "backend": backend,
            "tier": tier,
            "settings": settings,
            "dt": scene.dt,
            "steps": traj.n_steps,
            "brake_start": traj.brake_start,
            "error": error,
            "tolerance": self.tolerance,
            "fixed_inequalities": self.fixed_rows,
            "no_backend_call": sorted(set(range(traj.n_steps)) - set(self.per_step)),
            "problems": self.entries,
        }
        text = json.dumps(index, indent=1, allow_nan=False)
        (self.folder / INDEX).write_text(text + "\n", encoding="utf-8")
        return index


def applying(problem: solvers.Problem) -> tuple[solvers.Problem, NDArray[np.intp]]:
    """``problem`` with only its inequality rows that apply (finite ``h``; none: no ``G``), and
    the indices of those rows in ``problem``'s ``G``, shape (p',).

    A row ``0 · x ≤ +inf`` can never be active, but a checker that forms ``hᵀz`` (qpsolvers'
    duality gap, hence qpbenchmark's) gets ``inf · 0 = NaN`` from it."""
    if problem.G is None or problem.h is None:
        return problem, np.zeros(0, dtype=np.intp)
    rows = np.flatnonzero(np.isfinite(problem.h))
    G, h = (problem.G[rows], problem.h[rows]) if rows.size else (None, None)
    p = problem
    return solvers.Problem(p.P, p.q, p.A, p.b, G, h, p.lb, p.ub), rows


def active_rows(
    problem: solvers.Problem,
    x: NDArray[np.float64] | None,
    z: NDArray[np.float64] | None,
    z_box: NDArray[np.float64] | None,
    tolerance: float,
) -> dict[str, list[int]]:
    """The rows active at the accepted answer ``x`` (None: refused) with multipliers ``z``,
    ``z_box``, as indices: ``active_inequalities`` (rows of ``G`` whose slack ``h − G x`` is
    within ``tolerance`` or whose multiplier exceeds it), ``active_lower`` and
    ``active_upper`` (variables at a bound within it, or whose bound multiplier has that sign
    beyond it); all empty if refused."""
    rows: dict[str, list[int]] = {"active_inequalities": [], "active_lower": [], "active_upper": []}
    if x is None:
        return rows
    p, tol = problem, tolerance
    zb = np.zeros(p.n) if z_box is None else z_box
    if p.G is not None and p.h is not None:
        zg = np.zeros(p.n_in) if z is None else z
        rows["active_inequalities"] = np.flatnonzero((p.h - p.G @ x <= tol) | (zg > tol)).tolist()
    if p.lb is not None:
        rows["active_lower"] = np.flatnonzero((x - p.lb <= tol) | (zb < -tol)).tolist()
    if p.ub is not None:
        rows["active_upper"] = np.flatnonzero((p.ub - x <= tol) | (zb > tol)).tolist()
    return rows


def _target(folder: Path, force: bool) -> Path:
    """``folder`` if an export may be put there: new, empty, or an earlier export (``force``)."""
    if not str(folder).strip():
        raise ParameterError("output", "empty folder name")
    if folder.exists() and not folder.is_dir():
        raise ParameterError("output", f"{folder}: not a folder")
    if folder.is_dir() and any(folder.iterdir()):
        if not force:
            raise ParameterError(
                "output", f"{folder}: not empty (--force replaces an earlier export)"
            )
        if not _is_export(folder):
            raise ParameterError(
                "output",
                f"{folder}: not empty and not an export of dvqp "
                f"export-qps (no {INDEX} of one): not replaced",
            )
    return folder


def _is_export(folder: Path) -> bool:
    """``folder`` holds an index written by :func:`export_qps`."""
    try:
        format_ = json.loads((folder / INDEX).read_text(encoding="utf-8")).get("format")
        return format_ in FORMATS
    except (OSError, ValueError, AttributeError):
        return False


def _work_folder(target: Path) -> Path:
    """A new, empty folder beside ``target``, with the usual mode (``0o777 & ~umask``)."""
    parent = target.absolute().parent
    if not parent.is_dir():
        raise ParameterError("output", f"{parent}: no such directory")
    try:
        work = Path(tempfile.mkdtemp(dir=parent, prefix=f".{target.absolute().name}."))
    except OSError as exc:
        raise ParameterError("output", f"{parent}: cannot write here ({exc.strerror})") from exc
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(work, 0o777 & ~umask)
    return work


def _put_in_place(work: Path, target: Path) -> None:
    """Rename ``work`` to ``target``; an earlier export there is removed once it is done."""
    if not (target.is_dir() and any(target.iterdir())):
        os.replace(work, target)  # a missing or empty folder: replaced at once
        return
    old = Path(tempfile.mkdtemp(dir=target.absolute().parent, prefix=".old."))
    os.replace(target, old / "export")
    try:
        os.replace(work, target)
    except BaseException:
        os.replace(old / "export", target)
        raise
    finally:
        shutil.rmtree(old, ignore_errors=True)
