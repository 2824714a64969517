"""A planned trajectory, its per-step diagnostics, and its export (.npz, .csv)."""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from dvqp._files import atomic_file, output_path
from dvqp._inputs import Member, NpzArrays
from dvqp._versions import versions
from dvqp.errors import InputFileError
from dvqp.kinematics.developed_view import unwrap
from dvqp.limits.excess import StartBroken

if TYPE_CHECKING:
    from dvqp.retime import Retimed, RunScene

ARRAYS = (
    "t",
    "q",
    "qdot",
    "tool",
    "points",
    "w",
    "min_clearance",
    "solve_time",
    "step_time",
    "task_error",
    "iterations",
    "success",
    "status",
)
"""The arrays every trajectory file holds."""

DIAGNOSTICS = (
    "probe_clearance",
    "tilt",
    "self_distance",
    "limit_excess",
    "limits_kept",
    "substeps",
    "qddot",
    "solver_time",
    "link_height",
    "holder_height",
    "rail",
    "path_time",
    "level_error",
    "level_deviation",
    "level_measured",
)
"""Arrays added since dvqp 0.2; a file written before one was added lacks it (loaded empty)."""

CONVENTIONS = {
    "failed_steps": (
        "success is the mask of steps that were solved and kept every limit; a failed step "
        "has qdot = 0 (the arm held still) and task_error = +inf (no motion was computed)"
    ),
    "no_obstacles": "min_clearance and probe_clearance are +inf in a scene without obstacles",
    "units": "m, rad, s; tool = [l, z, h, alpha], l and alpha unwrapped",
}
"""What a reader of a trajectory file must know about its non-finite values; stored in the
``.npz`` as ``meta``. No array ever holds NaN."""


@dataclass(frozen=True)
class Trajectory:
    """Samples ``k = 0..N`` of a run and the ``N`` steps between them.

    Attributes
    ----------
    t : ndarray, shape (N+1,)
        Time, s.
    q : ndarray, shape (N+1, n)
        Joint configuration, rad.
    qdot : ndarray, shape (N, n)
        Joint velocity applied during step k, rad/s.
    tool : ndarray, shape (N+1, 4)
        Tool ``[l, z, h, α]`` with l (m) and α (rad) unwrapped along the run.
    points : ndarray, shape (N+1, k, 3)
        Body points ``[l, z, h]`` (m), l unwrapped per point.
    w : ndarray, shape (N+1,)
        Objective value.
    min_clearance, probe_clearance : ndarray, shape (N+1,)
        Smallest clearance to the obstacles of any guarded part (body points and links, probe
        and holder), and of the probe and its holder, m (inf: no obstacle).
    solve_time, solver_time, step_time : ndarray, shape (N,)
        Per step, s: the resolver's time (QP assembly + solve + check, or the pseudoinverse),
        of it the time in the QP backend's calls (the baseline: its linear algebra), and the
        full step's (kinematics + objective + resolver).
    task_error : ndarray, shape (N,)
        ``‖J̄Q̇ − ẋ‖∞`` per step.
    iterations : ndarray of int, shape (N,)
        Solver iterations (−1: not reported).
    success : ndarray of bool, shape (N,)
        The step was solved and checked.
    status : ndarray of str, shape (N,)
        Resolver status per step.
    backend, pipe_radius, scene_text : str, float, str
        The resolver's name, the pipe radius (m) and the scene file's text (if any).
    tracking_error : ndarray, shape (N+1, 4) or (0, 4)
        ``x_d − x`` of the tool per sample (m, m, m, rad; l and α wrapped) against the planned
        reference (a path, or the integrated JOG commands); empty if there was none.
    tilt : ndarray, shape (N+1,)
        Angle of the probe axis from the pipe's radial direction, rad, in [0, π].
    limit_excess : ndarray, shape (N+1,)
        Exact excess (m or rad) of the worst limit (relative to its tolerance) at each sample,
        against ``min(bound, value at the start)``; 0 where every limit is kept.
    limits_kept : ndarray of bool, shape (N+1,)
        Every limit is kept at the sample to within its tolerance (0.1 mm, 1 mrad, 1 µrad).
    substeps : ndarray of int, shape (N,)
        Substeps the step was split into to keep every limit (1: not split).
    self_distance : ndarray, shape (N+1,)
        Smallest 3-D distance between two non-adjacent links of the arm (the probe holder
        included), m.
    link_height, holder_height : ndarray, shape (N+1,) or (0,)
        The lowest height over the pipe surface (m) of the body links and the carriage link,
        and of the probe holder (last body point to the tool): each link the lowest point of
        its real straight 3-D chord (an end's own height where that is lowest); empty in a
        file written before they were recorded.
    rail : ndarray, shape (N+1, 3) or (0, 3)
        ``[l, z, h]`` of the rail point (where the carriage rides its rail; the carriage link
        runs from it to body point 1), m, l as recorded (in ``(−πR, πR]``); empty for an arm
        without one, a console recording, or a file written before it was recorded.
    path_time : ndarray, shape (N+1,) or (0,)
        Nominal schedule's time reached at each sample, s (fixed timing: ``t`` until the stop).
    qddot : ndarray, shape (N, n)
        Joint acceleration at the start of each step, ``(qdot[k] − qdot[k−1]) / dt`` with the
        run starting at rest, rad/s².
    start_broken : tuple of StartBroken
        The limits the start already broke (``limit_excess`` counts them from their start
        value) that the samples break against their true bound: each value, its bound, its
        value at the start and its lowest (empty: none; files written before it was added
        load with none).
    brake_start : int
        The first step of the stop that ends the run at rest (steps ``brake_start..N−1`` brake,
        with the tool held still; ``N`` if the run needed none): −1 if the run was not stopped
        (``stop=False``, or an older file).
    refusals : dict of str to int
        QP backend calls that gave no accepted answer, by kind (``"infeasible"``,
        ``"iteration limit"``, ``"inaccurate"``…, :data:`solvers.REFUSALS`); the step then
        took the relaxed or braking path (empty: none, the baseline, or an older file).
    accuracy : dict of str to float
        qpbenchmark's accuracy of the steps' QP answers (:mod:`solvers.accuracy`,
        :attr:`dvqp.resolution.qp.QPSolver.accuracy`): ``solves``,
        ``unanswered`` and the shifted geometric means ``primal_residual``, ``dual_residual``,
        ``duality_gap`` (empty: the baseline, or an older file).
    levels : tuple of str
        The levels of the hard tasks, by priority (1 first): what each holds (``"tool h,
        alpha"``; empty: an older file).
    level_error : ndarray, shape (N, L) or (0, 0)
        Each level's residual ``‖A_k Q̇ − b_k‖∞`` per step (task units per s, m/s or rad/s;
        ``inf`` for a failed step): 0 to the solver's tolerance where the level was kept
        exactly, larger where it gave way. With one level, ``task_error``.
    level_deviation : ndarray, shape (N+1, L, 2) or (0, 0, 2)
        Each level's worst error per sample against what its tasks hold (the tool against the
        commanded motion, a point or posture against its target; :meth:`dvqp.Task.deviation`):
        ``[length (m), angle (rad)]``, 0 where ``level_measured`` is False.
    level_measured : ndarray of bool, shape (L, 2) or (0, 2)
        Whether a level's ``level_deviation`` has a length (its tasks hold one) and an angle.
    """

    t: NDArray[np.float64]
    q: NDArray[np.float64]
    qdot: NDArray[np.float64]
    tool: NDArray[np.float64]
    points: NDArray[np.float64]
    w: NDArray[np.float64]
    min_clearance: NDArray[np.float64]
    solve_time: NDArray[np.float64]
    step_time: NDArray[np.float64]
    task_error: NDArray[np.float64]
    iterations: NDArray[np.int64]
    success: NDArray[np.bool_]
    status: NDArray[np.str_]
    backend: str = ""
    pipe_radius: float = 0.0
    scene_text: str = field(default="", repr=False)
    tracking_error: NDArray[np.float64] = field(default_factory=lambda: np.zeros((0, 4)))
    probe_clearance: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    tilt: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    limit_excess: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    limits_kept: NDArray[np.bool_] = field(default_factory=lambda: np.zeros(0, dtype=bool))
    substeps: NDArray[np.int64] = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    self_distance: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    qddot: NDArray[np.float64] = field(default_factory=lambda: np.zeros((0, 0)))
    solver_time: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    link_height: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    holder_height: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    rail: NDArray[np.float64] = field(default_factory=lambda: np.zeros((0, 3)))
    path_time: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    start_broken: tuple[StartBroken, ...] = ()
    brake_start: int = -1
    refusals: dict[str, int] = field(default_factory=dict)
    accuracy: dict[str, float] = field(default_factory=dict)
    levels: tuple[str, ...] = ()
    level_error: NDArray[np.float64] = field(default_factory=lambda: np.zeros((0, 0)))
    level_deviation: NDArray[np.float64] = field(default_factory=lambda: np.zeros((0, 0, 2)))
    level_measured: NDArray[np.bool_] = field(default_factory=lambda: np.zeros((0, 2), dtype=bool))

    @classmethod
    def from_samples(
        cls,
        *,
        dt: float,
        pipe_radius: float,
        backend: str,
        tool: NDArray[np.float64],
        points: NDArray[np.float64],
        status: Sequence[str],
        **arrays: NDArray[np.float64],
    ) -> Trajectory:
        """Build from raw samples, unwrapping l (period 2πR) and α (period 2π).

        ``arrays`` are the other fields (``q``, ``qdot``, ``w``, ...), taken as they are.
        """
        period = 2.0 * np.pi * pipe_radius
        # l continuous along the body (points then tool) at the first sample, then in time.
        first = unwrap(np.append(points[0, :, 0], tool[0, 0]), period)
        pts = points.copy()
        pts[0, :, 0] = first[:-1]
        pts[:, :, 0] = unwrap(pts[:, :, 0], period, axis=0)
        unwrapped = tool.copy()
        unwrapped[0, 0] = first[-1]
        unwrapped[:, 0] = unwrap(unwrapped[:, 0], period)
        unwrapped[:, 3] = unwrap(tool[:, 3], 2.0 * np.pi)
        return cls(
            t=dt * np.arange(tool.shape[0]),
            tool=unwrapped,
            points=pts,
            status=np.asarray(list(status), dtype=np.str_),
            backend=backend,
            pipe_radius=float(pipe_radius),
            **arrays,
        )  # type: ignore[arg-type]

    @property
    def n_steps(self) -> int:
        """Number of steps N."""
        return int(self.qdot.shape[0])

    @property
    def braking_time(self) -> float | None:
        """How long the stop at the end took, s (None: the run was not stopped)."""
        if self.brake_start < 0:
            return None
        steps = self.n_steps - self.brake_start
        return float(steps * self.t[1]) if steps else 0.0  # t[1] is dt

    @property
    def refused(self) -> str:
        """``"10 infeasible, 2 iteration limit"``: :attr:`refusals`, most first (``""``: none)."""
        ranked = sorted(self.refusals.items(), key=lambda item: (-item[1], item[0]))
        return ", ".join(f"{count} {kind}" for kind, count in ranked)

    @property
    def ok(self) -> bool:
        """Every step succeeded."""
        return bool(np.all(self.success))

    def retimed(self, scene: RunScene, rate: float | None = None) -> Retimed:
        """This run's path as fast as ``scene``'s joint velocity and acceleration limits
        allow, from rest to rest, sampled at ``rate`` Hz (default
        :data:`dvqp.retime.DEFAULT_RATE`) and verified exactly: :func:`dvqp.retime.retime`
        (needs toppra, ``pip install 'dvqp[retime]'``)."""
        from dvqp.retime import DEFAULT_RATE, retime

        return retime(scene, self.q, self.t, DEFAULT_RATE if rate is None else rate)

    def save(self, path: str | Path) -> Path:
        """Write ``.npz`` (all arrays, metadata, scene text) or ``.csv`` atomically.

        The CSV has one row per sample and the columns ``t, q1..qn, qdot1..qdotn, l, z, h,
        alpha`` and, if the trajectory has a tracking error, ``e_l, e_z, e_h, e_alpha``.
        ``qdot`` on a row is the joint velocity applied from that sample to the next (0 on
        the last row: the motion has ended). The ``.npz`` also holds ``meta``, a JSON text
        with the versions of dvqp, numpy, Pinocchio and the solvers, and the file's
        conventions (:data:`CONVENTIONS`). The file appears complete or not at all.
        """
        target = output_path(path, (".npz", ".csv"))
        with atomic_file(target) as tmp, open(tmp, "wb") as fh:
            if target.suffix.lower() == ".npz":
                arrays = {name: getattr(self, name) for name in (*ARRAYS, *DIAGNOSTICS)}
                np.savez_compressed(
                    fh,
                    **arrays,
                    backend=np.str_(self.backend),
                    pipe_radius=np.float64(self.pipe_radius),
                    scene=np.str_(self.scene_text),
                    tracking_error=self.tracking_error,
                    start_broken=np.str_(json.dumps([asdict(b) for b in self.start_broken])),
                    brake_start=np.int64(self.brake_start),
                    refusals=np.str_(json.dumps(self.refusals)),
                    accuracy=np.str_(json.dumps(self.accuracy)),
                    levels=np.str_(json.dumps(list(self.levels))),
                    meta=np.str_(json.dumps({"versions": versions(), **CONVENTIONS})),
                )
            else:
                self._write_csv(fh)
        return target

    def _write_csv(self, fh: object) -> None:
        n = self.q.shape[1]
        header = [
            "t",
            *(f"q{i + 1}" for i in range(n)),
            *(f"qdot{i + 1}" for i in range(n)),
            "l",
            "z",
            "h",
            "alpha",
        ]
        qdot = np.vstack([self.qdot, np.zeros((1, n))])
        columns = [self.t, self.q, qdot, self.tool]
        if self.tracking_error.shape[0] == self.t.shape[0]:
            header += ["e_l", "e_z", "e_h", "e_alpha"]
            columns.append(self.tracking_error)
        table = np.column_stack(columns)
        np.savetxt(fh, table, delimiter=",", header=",".join(header), comments="", fmt="%.10g")  # type: ignore[arg-type]

    @classmethod
    def load(cls, path: str | Path) -> Trajectory:
        """Read a trajectory written by :meth:`save` (``.npz``).

        Every array's declared shape and size is checked before any is inflated
        (:func:`check_members`), so a damaged or hostile file costs no more memory than its
        arrays declare, and those must fit a trajectory of the samples its ``t`` declares.

        Raises
        ------
        InputFileError
            ``<path>: cannot read: <reason>``, or ``<path>: not a dvqp trajectory
            (<reason>)``: not an ``.npz`` file, damaged, a missing array, an array of a shape
            or size no trajectory has, pickled objects.
        """
        with NpzArrays(path, "a dvqp trajectory") as npz:
            try:
                names = check_members(npz.members)
            except ValueError as exc:
                raise npz.refused(str(exc)) from exc
            npz.check_memory(names)
            data = {name: npz.read(name) for name in names}
        try:
            return cls._from_arrays(data)
        except (KeyError, ValueError, TypeError) as exc:
            missing = isinstance(exc, KeyError)
            reason = "not written by 'dvqp plan'" if missing else "not a dvqp .npz file"
            raise InputFileError(path, f"not a dvqp trajectory ({reason})") from exc

    @classmethod
    def _from_arrays(cls, data: dict[str, np.ndarray]) -> Trajectory:
        """The trajectory of a file's arrays (files written before 0.2 call the tool's DV
        coordinates ``dv``)."""
        arrays = {name: data["dv" if name == "tool" and "dv" in data else name] for name in ARRAYS}
        optional = (*DIAGNOSTICS, "tracking_error")
        arrays.update({name: data[name] for name in optional if name in data})
        broken = json.loads(str(data["start_broken"])) if "start_broken" in data else []
        return cls(
            **arrays,
            start_broken=tuple(StartBroken(**b) for b in broken),
            backend=str(data["backend"]),
            pipe_radius=float(data["pipe_radius"]),
            scene_text=str(data["scene"]),
            brake_start=int(data["brake_start"]) if "brake_start" in data else -1,
            refusals=_counts(data, "refusals"),
            accuracy=_counts(data, "accuracy"),
            levels=_names(data, "levels"),
        )


MAX_WIDTH = 4096
"""Most values a sample (or a step) of a trajectory file's array holds: ``points`` holds 3 a
body point, so up to 1365 body points."""
MAX_TEXT = 1 << 24
"""Most characters of a text a trajectory file holds (its scene's text: a scene file is at
most 16 MiB, :data:`dvqp.scenes.scene.MAX_BYTES`)."""
TEXTS = ("backend", "scene", "start_broken", "refusals", "accuracy", "levels", "meta")
"""A trajectory file's texts (0-d string arrays)."""
NUMBERS = ("pipe_radius", "brake_start")
"""A trajectory file's single numbers."""
PER_LEVEL = ("level_measured",)
"""A trajectory file's arrays of a row per task level (not per sample): at most
:data:`MAX_WIDTH` levels."""


def check_members(members: dict[str, Member]) -> list[str]:
    """The members of a trajectory file that :meth:`Trajectory.load` reads, checked before
    any is inflated: every array's rows are the samples ``t`` declares (or the steps between
    them, or none), with at most :data:`MAX_WIDTH` numbers a row; texts and numbers are
    single values, a text at most :data:`MAX_TEXT` characters.

    Raises
    ------
    ValueError
        What is wrong (``member 'q': 20000000 rows for 1000 samples``).
    """
    t = members.get("t")
    if t is None:
        raise ValueError("not written by 'dvqp plan'")
    if len(t.shape) != 1 or t.shape[0] < 1:
        raise ValueError(f"member 't': shape {t.shape}, not (samples,)")
    samples = t.shape[0]
    names = [n for n in (*ARRAYS, *DIAGNOSTICS, "tracking_error", "dv") if n in members]
    for name in names:
        m = members[name]
        if name in PER_LEVEL:
            if len(m.shape) != 2 or m.shape[0] > MAX_WIDTH or m.shape[1] != 2:
                raise ValueError(f"member {name!r}: shape {m.shape}, not (levels, 2)")
            continue
        if not m.shape or m.shape[0] not in (samples, samples - 1, 0):
            rows = m.shape[0] if m.shape else "no"
            raise ValueError(f"member {name!r}: {rows} rows for {samples} samples")
        width = m.width * (m.dtype.itemsize // 4 if m.dtype.kind == "U" else 1)
        if width > MAX_WIDTH:
            raise ValueError(f"member {name!r}: {width} values a row (at most {MAX_WIDTH})")
    for name in (n for n in (*TEXTS, *NUMBERS) if n in members):
        m = members[name]
        if m.shape or (name in TEXTS and m.dtype.itemsize > 4 * MAX_TEXT):
            raise ValueError(f"member {name!r}: not a single value of a trajectory file")
    return [*names, *(n for n in (*TEXTS, *NUMBERS) if n in members)]


def _names(data: Any, name: str) -> tuple[str, ...]:
    """The JSON list of strings ``name`` of a loaded file (``()``: none in it)."""
    if name not in data:
        return ()
    names = json.loads(str(data[name]))
    if not isinstance(names, list) or not all(isinstance(n, str) for n in names):
        raise ValueError(name)
    return tuple(names)


def _counts(data: Any, name: str) -> dict[str, Any]:
    """The JSON object ``name`` of a loaded file, values as numbers (``{}``: none in it)."""
    if name not in data:
        return {}
    counts = json.loads(str(data[name]))
    if not isinstance(counts, dict):
        raise ValueError(name)
    number = int if name == "refusals" else float
    return {str(key): number(value) for key, value in counts.items()}
