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
from dvqp._files import output_folder
from dvqp._inputs import read_bounded
from dvqp._versions import __version__
from dvqp.errors import (
    InputFileError,
    LimitViolationError,
    OutputError,
    ParameterError,
    UnreachableTargetError,
    one_line,
)
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
    """What :func:`export_qps` wrote: the ``folder`` (its real path: ``.``, ``..`` and
    symbolic links resolved), the run's ``trajectory`` and the ``index`` (the contents of
    ``index.json``)."""

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

    ``folder`` is checked before the run (:func:`export_folder`). The files are written into
    a temporary folder (beside a new ``folder``, inside an existing one) and moved into place
    once all are written, the index last: an error or an interrupt (Ctrl-C, ``SIGTERM``
    under :func:`dvqp.cli.progress.interruptible`) leaves nothing behind and an earlier
    export as it was. A failed run is exported too (its index's ``error`` says why
    :func:`~dvqp.run.planning.check_run` fails it).

    Parameters
    ----------
    scene, backend
        What to run; ``backend`` a QP backend's name (not ``"pinv"``: it solves no QP).
    folder
        The export's folder: new, empty, or (``force``) an earlier export holding nothing
        else, whose files are replaced (symbolic links followed: a linked folder is filled,
        the link kept).
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
        ``backend`` is ``pinv``; ``folder`` cannot take the export (:func:`export_folder`).
    OutputError
        The files could not be written (a full disk).
    """
    if check_name(backend) == PINV:
        raise ParameterError("backend", "pinv solves no QP: name a QP backend (see dvqp backends)")
    real = export_folder(folder, force)
    work = _work_folder(real)
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
        _put_in_place(work, real, Path(folder))
    except BaseException as exc:
        if isinstance(exc, OSError) and not isinstance(exc, OutputError):
            raise OutputError(folder, exc.strerror or str(exc), exc.errno) from exc
        raise
    finally:
        shutil.rmtree(work, ignore_errors=True)  # moved into place, or left: removed
    return Exported(real, traj, index)


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


MAX_INDEX_BYTES = 1 << 28
"""Largest index read to find out what an earlier export wrote (256 MiB: some 500 000
problems)."""


def export_folder(folder: str | Path, force: bool = False) -> Path:
    """The folder an export to ``folder`` fills, checked before any work (its real path:
    ``.``, ``..`` and symbolic links resolved, :func:`dvqp._files.output_folder`).

    It is new, or empty, or (``force``) an earlier export that holds nothing but what its
    index lists: ``--force`` replaces only the files an earlier export wrote.

    Raises
    ------
    ParameterError
        ``output: empty file name``; ``output: <folder>: not a folder``, ``… read-only: not
        replaced``, ``… not empty (--force replaces an earlier export)``, ``… not an export
        of dvqp export-qps (…): not replaced``, ``… --force replaces only what an earlier
        export wrote; it also holds 2 other files: notes.txt, answers/x.npz (move them
        away)``; a parent that is missing or cannot be written in.
    """
    real = output_folder(folder)
    if not real.is_dir() or not any(real.iterdir()):
        return real
    if not force:
        raise ParameterError("output", f"{folder}: not empty (--force replaces an earlier export)")
    listed = exported_files(real, folder)
    other = _other_files(real, listed)
    if other:
        shown = ", ".join(other[:5]) + (", …" if len(other) > 5 else "")
        raise ParameterError(
            "output",
            f"{folder}: --force replaces only what an earlier export wrote; it also holds "
            f"{len(other)} other file{'s' * (len(other) > 1)}: {shown} (move them away)",
        )
    return real


def exported_files(real: Path, shown: str | Path) -> set[str]:
    """The files an earlier export in the folder ``real`` wrote, by their path in it (its
    index, its problems, ``answers/<name>`` and, from format 2 on, qpbenchmark's test set),
    from its index.

    Raises
    ------
    ParameterError
        ``output: <shown>: not empty and not an export of dvqp export-qps (<why>): not
        replaced``: no index, one that cannot be read, is damaged, is not an export's, or
        lists a file outside the folder.
    """
    try:
        if not (real / INDEX).is_file():
            raise ValueError(f"no {INDEX}")
        text = read_bounded(real / INDEX, MAX_INDEX_BYTES, "an export's index")
        index = json.loads(text)
        if not isinstance(index, dict) or index.get("format") not in FORMATS:
            raise ValueError(f"{INDEX} is not an export's index")
        files = {INDEX, TEST_SET} if index["format"] == FORMAT else {INDEX}
        for entry in index["problems"]:
            files |= {_plain(entry["file"]), f"{ANSWERS}/{_plain(entry['answer'], ANSWERS)}"}
    except (InputFileError, ValueError, KeyError, TypeError, RecursionError) as exc:
        why = exc.reason if isinstance(exc, InputFileError) else _why(exc)
        raise ParameterError(
            "output",
            f"{shown}: not empty and not an export of dvqp export-qps ({why}): not replaced",
        ) from exc
    return files


def _plain(name: object, folder: str = "") -> str:
    """A file name an index lists (``folder/<name>`` if ``folder``): ``name``; a ValueError
    if it is not a plain name of a file in the export."""
    text = str(name) if isinstance(name, str) else ""
    if folder:
        head, _, text = text.partition("/")
        text = text if head == folder else ""
    if not text or "/" in text or "\\" in text or text in (".", "..") or "\0" in text:
        raise ValueError(f"{INDEX} lists {one_line(repr(name))}, not a file of the export")
    return text


def _why(exc: BaseException) -> str:
    """Why an index was not read, in a few words."""
    if isinstance(exc, json.JSONDecodeError):
        return f"{INDEX}: not JSON ({exc.msg}, line {exc.lineno})"
    if isinstance(exc, KeyError | TypeError):
        return f"{INDEX} is not an export's index"
    if isinstance(exc, RecursionError):
        return f"{INDEX}: nested too deeply"
    return one_line(str(exc))


def _other_files(real: Path, listed: set[str]) -> list[str]:
    """What the folder ``real`` holds beyond the files ``listed`` and an ``answers`` folder:
    paths in it, a folder's with a trailing ``/``."""
    answers = real / ANSWERS
    ours = answers.is_dir() and not answers.is_symlink()
    other = [n for n in _unlisted(real, listed) if not (ours and n == f"{ANSWERS}/")]
    if ours:
        inner = {n.partition("/")[2] for n in listed if n.startswith(f"{ANSWERS}/")}
        other += [f"{ANSWERS}/{n}" for n in _unlisted(answers, inner)]
    return sorted(other)


def _unlisted(folder: Path, listed: set[str]) -> list[str]:
    """The entries of ``folder`` that are not regular files named in ``listed``."""
    return [
        entry.name + ("/" if entry.is_dir() else "")
        for entry in folder.iterdir()
        if entry.name not in listed or entry.is_symlink() or not entry.is_file()
    ]


def _work_folder(real: Path) -> Path:
    """A new, empty folder for the files of an export to ``real``, with the usual mode
    (``0o777 & ~umask``): inside ``real`` if it exists, else beside it."""
    where, prefix = (real, ".dvqp-export.") if real.is_dir() else (real.parent, f".{real.name}.")
    try:
        work = Path(tempfile.mkdtemp(dir=where, prefix=prefix))
    except OSError as exc:
        raise ParameterError("output", f"{where}: cannot write here ({exc.strerror})") from exc
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(work, 0o777 & ~umask)
    return work


def _put_in_place(work: Path, real: Path, shown: Path) -> None:
    """Move the export written in ``work`` to ``real``: renamed to it if it is new; into it
    if it exists (the folder itself kept: its mode, a link to it, a shell in it), after the
    files of an earlier export there, its index first, were moved out of the way. The new
    index comes last. Any failure moves everything back: the earlier export as it was."""
    if not real.is_dir():
        os.rename(work, real)
        return
    trash = Path(tempfile.mkdtemp(dir=real, prefix=".dvqp-old."))
    done: list[tuple[Path, Path]] = []  # (from, to) of every move made, to undo
    try:
        old = exported_files(real, shown) if (real / INDEX).exists() else set()
        (trash / ANSWERS).mkdir()
        for name in sorted(old, key=lambda n: (n != INDEX, n)):
            if os.path.lexists(real / name):
                _move(real / name, trash / name, done)
        if (real / ANSWERS).is_dir() and not (real / ANSWERS).is_symlink():
            _move(real / ANSWERS, trash / f"{ANSWERS}.left", done)  # empty, or not ours
            if any((trash / f"{ANSWERS}.left").iterdir()):
                raise ParameterError("output", f"{shown}: {ANSWERS}/ gained files during the run")
        for entry in sorted(work.iterdir(), key=lambda e: (e.name == INDEX, e.name)):
            if os.path.lexists(real / entry.name):
                raise ParameterError(
                    "output", f"{shown}: {entry.name} appeared during the run: not replaced"
                )
            _move(entry, real / entry.name, done)
    except BaseException:
        for source, target in reversed(done):
            os.rename(target, source)
        raise
    finally:
        shutil.rmtree(trash, ignore_errors=True)


def _move(source: Path, target: Path, done: list[tuple[Path, Path]]) -> None:
    """Rename ``source`` to ``target`` and note it in ``done``."""
    os.rename(source, target)
    done.append((source, target))
