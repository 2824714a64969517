"""What the command line prints and writes: the comparison table, a run's summary, CSV.

The rows are those of :func:`dvqp.run.comparison.summarize`; an undefined figure (None) is shown
as ``-`` in the table and as an empty CSV cell (:func:`dvqp.run.comparison.rows_to_csv`).
"""

from __future__ import annotations

import textwrap
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from dvqp.cli.figures import write_atomic
from dvqp.errors import one_line
from dvqp.limits import start_broken_lines
from dvqp.run.comparison import Row
from dvqp.run.comparison import rows_to_csv as rows_to_csv  # part of this module's API (docs)
from dvqp.run.levels import level_figures
from dvqp.run.table_text import aligned, cell

if TYPE_CHECKING:
    from dvqp.motion.trajectory import Trajectory
    from dvqp.scenes.scene import Scene

TABLE = (  # (row key, header, format)
    ("scene", "scene", "{}"),
    ("backend", "backend", "{}"),
    ("success", "ok", "{}"),
    ("tracked", "tracked", "{}"),
    ("max_task_error", "task err", "{:.1e}"),
    ("min_clearance", "clear m", "{:+.4f}"),
    ("median_step_us", "step us", "{:.0f}"),
    ("median_solver_us", "solv us", "{:.1f}"),
    ("primal_residual", "r_prim", "{:.0e}"),
)
"""Columns of :func:`format_table` by default, the figures a reader decides on, in at most
100 characters: (row key, header, format of a defined value)."""

WIDE_TABLE = (  # (row key, header, format)
    ("scene", "scene", "{}"),
    ("backend", "backend", "{}"),
    ("success", "ok", "{}"),
    ("tracked", "tracked", "{}"),
    ("steps", "steps", "{}"),
    ("median_step_us", "med us", "{:.0f}"),
    ("p95_step_us", "p95 us", "{:.0f}"),
    ("median_solver_us", "solver us", "{:.1f}"),
    ("median_rest_us", "rest us", "{:.1f}"),
    ("median_iterations", "iters", "{:.0f}"),
    ("ratio_to_pinv", "x pinv", "{:.2f}"),
    ("max_task_error", "task err", "{:.1e}"),
    ("min_clearance", "clearance m", "{:+.4f}"),
    ("closest", "closest", "{}"),
    ("min_self_distance", "self m", "{:.3f}"),
    ("max_joint_acceleration", "qdd", "{:.3g}"),
    ("max_limit_excess", "excess", "{:.2g}"),
    ("max_joint_limit_violation", "q viol rad", "{:.3g}"),
    ("max_velocity_limit_violation", "qd viol rad/s", "{:.3g}"),
    ("slowed", "slowed", "{}"),
    ("relaxed", "relaxed", "{}"),
    ("max_deviation", "path dev m", "{:.2g}"),
    ("refused_calls", "refused", "{}"),
    ("primal_residual", "r_prim", "{:.1e}"),
    ("dual_residual", "r_dual", "{:.1e}"),
    ("duality_gap", "gap", "{:.1e}"),
    ("substepped", "split", "{}"),
    ("failures", "fails", "{}"),
    ("final_joint_speed", "end qd", "{:.3g}"),
    ("braking_time", "brake s", "{:.3f}"),
    ("levels_gave_way", "levels gave way", "{}"),
    ("levels_least_squares", "least squares", "{}"),
)
"""Every column (``--wide``)."""


def format_table(rows: Sequence[Row], wide: bool = False) -> str:
    """The comparison as an aligned text table, a header and a rule first (``-``: undefined):
    the :data:`TABLE` columns, or with ``wide`` every one (:data:`WIDE_TABLE`)."""
    columns = WIDE_TABLE if wide else TABLE
    table = [[h for _, h, _ in columns]]
    table += [[cell(r.get(k), f) for k, _, f in columns] for r in rows]
    return aligned(table, left=2)


def footer_lines(rows: Sequence[Row], width: int = 100) -> list[str]:
    """Why a run is not ``ok`` (its error) or ``ok`` but not ``tracked`` (safe, every limit
    kept, yet the tool left the commanded motion), and how each level of a run with more than
    one fared, wrapped to ``width`` characters."""
    notes = []
    for r in rows:
        name = f"{r['scene']} / {r['backend']}"
        if r.get("level_detail"):
            notes.append(f"{name}: {r['level_detail']}")
        if r["error"]:
            notes.append(f"{name}: {r['error']}")
        elif r.get("tracked") is False:
            refused = f"; {r['refused_calls']} backend calls refused" if r["refused_calls"] else ""
            notes.append(
                f"{name}: ok (every limit kept) but not tracked: the tool was up to "
                f"{r['max_tracking_error'] * 1e3:.3g} mm and {r['max_heading_error']:.3g} rad "
                f"from the commanded motion{refused}"
            )
    wrap = textwrap.TextWrapper(width, initial_indent="  ", subsequent_indent="    ")
    return [line for note in notes for line in wrap.wrap(note)]


def format_summary(scene: Scene, traj: Trajectory, row: Row, output: Path | None) -> str:
    """What ``dvqp plan`` prints about a run: ``row`` from :func:`dvqp.run.comparison.summarize`,
    ``output`` the file the trajectory was saved to (or None); a line longer than 100
    characters is wrapped, its continuation two columns right of the value (a file name
    never)."""
    tool = traj.tool[-1]
    lines = [
        f"scene           {scene.name} ({one_line(scene.source)}), {scene.mode} mode",
        f"backend         {traj.backend}",
        f"steps           {_steps(row)}",
        f"result          {_result(row)}",
        *_levels(traj),
        f"max task error  {cell(row['max_task_error'], '{:.2e}')}",
        f"min clearance   {cell(row['min_clearance'], '{:+.4f} m')}"
        + (f" ({row['closest']})" if row["closest"] else ""),
        f"probe           clearance {cell(row['min_probe_clearance'], '{:+.4f} m')}, "
        f"tilt from radial >= {cell(row['min_tilt'], '{:.3f} rad')}",
        f"self distance   {cell(row['min_self_distance'], '{:.4f} m')}"
        + (f" ({row['closest_pair']})" if row["closest_pair"] else ""),
        *([_heights(row, traj)] if traj.link_height.size else []),  # absent in old files
        f"acceleration    max |qdd| {cell(row['max_joint_acceleration'], '{:.3g} rad/s^2')}",
        f"limits          {_limits(row, traj)}",
        f"step time       median {cell(row['median_step_us'], '{:.0f}')} us, "
        f"p95 {cell(row['p95_step_us'], '{:.0f}')} us",
        f"solver          {cell(row['median_solver_us'], '{:.1f}')} us a step in the solver's "
        f"calls, {cell(row['median_rest_us'], '{:.1f}')} us the rest, "
        f"{cell(row['median_iterations'], '{:.0f}')} iterations (medians)"
        + (f"; {row['refused_calls']} calls refused ({traj.refused})" if traj.refusals else ""),
        *([_accuracy(row)] if row["qp_solves"] else []),
        f"final tool DV   l = {tool[0]:.4f} m, z = {tool[1]:.4f} m, h = {tool[2]:.4f} m, "
        f"alpha = {tool[3]:.4f} rad",
    ]
    lines.append(f"end             {_end(traj, row)}")
    if row.get("nominal_duration") is not None:
        lines.append(_path(row))
    if row["final_tracking_error"] is not None:
        lines.append(
            f"final deviation {row['final_tracking_error'] * 1e3:.3g} mm from the commanded motion"
        )
    wrap = textwrap.TextWrapper(
        100, subsequent_indent=" " * 18, break_long_words=False, break_on_hyphens=False
    )
    body = [w for line in lines[1:] for part in line.split("\n") for w in wrap.wrap(part)]
    saved = [f"saved           {output}"] if output is not None else []
    return "\n".join([lines[0], *body, *saved])  # the file names never wrapped


def _levels(traj: Trajectory) -> list[str]:
    """``level 1         tool h, alpha: kept exactly; worst error 0.0068 mm, 4.8e-05 rad``: one
    line a level, for a run with more than one."""
    levels = level_figures(traj)
    if len(levels) < 2:
        return []
    return [f"{f'level {k}':<16}{level.name}: {level.words()}" for k, level in enumerate(levels, 1)]


def _accuracy(row: Row) -> str:
    """qpbenchmark's figures of the backend calls (shifted geometric means)."""
    return (
        f"accuracy        primal residual {row['primal_residual']:.1e}, dual residual "
        f"{row['dual_residual']:.1e}, duality gap {row['duality_gap']:.1e} (shifted geometric "
        f"means over {row['qp_solves']} QP answers, {row['settings']} settings)"
    )


def _path(row: Row) -> str:
    """``path            followed in 3.750 s (nominal 3.390 s), 171 steps slowed; worst
    deviation 0.55 mm``."""
    slowed = f", {row['slowed']} steps slowed" if row["slowed"] else ""
    return (
        f"path            followed in {row['path_duration']:.3f} s (nominal "
        f"{row['nominal_duration']:.3f} s){slowed}; worst deviation from it "
        f"{row['max_deviation'] * 1e3:.3g} mm"
    )


def _heights(row: Row, traj: Trajectory) -> str:
    """``link heights    lowest +0.0500 m (link4), holder +0.0417 m``: the lowest point of the
    body and carriage links' chords (and that link) and of the probe holder."""
    where = f" ({row['lowest_link']})" if row["lowest_link"] else ""
    holder = cell(min(traj.holder_height, default=None), "{:+.4f} m")
    low = cell(row["min_link_height"], "{:+.4f} m")
    return f"link heights    lowest {low}{where}, holder {holder}"


def _result(row: Row) -> str:
    """``safe to send`` (and how much of the task gave way; whether the tool tracked the
    commanded motion, the verdict ``compare`` gives), or ``NOT OK``."""
    if not row["success"]:
        return "NOT OK"
    gave_way = row["relaxed"] + (row.get("braking") or 0)
    text = "safe to send: every limit kept"
    counts = [int(c) for c in (row.get("levels_gave_way") or "").split("/") if c]
    if gave_way and any(counts):  # which levels: "level 3 on 1886"
        which = ", ".join(f"level {k} on {c}" for k, c in enumerate(counts, 1) if c)
        text += f"; a level gave way on {gave_way} of {row['steps']} steps ({which})"
    elif gave_way:
        text += f"; the task gave way on {gave_way} of {row['steps']} steps"
    if row.get("tracked") is False:
        text += (
            f"; not tracked: the tool was up to {row['max_tracking_error'] * 1e3:.3g} mm and "
            f"{row['max_heading_error']:.3g} rad from the commanded motion"
        )
    return text


def _steps(row: Row) -> str:
    """``"720: 657 optimal, 63 relaxed, 0 failed; 3 split into substeps"`` (and ``slowed``
    steps where there are any)."""
    steps, relaxed, fails = row["steps"], row["relaxed"], row["failures"]
    braking, slowed = row.get("braking") or 0, row.get("slowed") or 0
    text = f"{steps}: {steps - slowed - relaxed - braking - fails} optimal, "
    text += f"{slowed} slowed, " if slowed else ""
    text += f"{relaxed} relaxed, "
    text += f"{braking} braking, {fails} failed" if braking else f"{fails} failed"
    return text + (f"; {row['substepped']} split into substeps" if row["substepped"] else "")


def _limits(row: Row, traj: Trajectory) -> str:
    """That every limit was kept (and the deepest excess within tolerance), or the worst one
    broken, and each limit the start broke (one line each)."""
    worst = (
        f"{row['worst_limit']} past its bound by {row['max_limit_excess']:.2g}"
        if row["worst_limit"]
        else "a limit given to plan, not named here"
    )
    lines = start_broken_lines(traj.start_broken)
    if not traj.limits_kept.all():
        lines.insert(0, f"BROKEN: {worst}")
    elif not lines:
        lines = [
            "every limit kept"
            + (f" to its tolerance (deepest: {worst})" if row["worst_limit"] else "")
        ]
    return "\n                ".join(lines)


def _end(traj: Trajectory, row: Row) -> str:
    """``at rest after 0.025 s of braking (5 steps)``, or the final joint speed."""
    speed, time = row["final_joint_speed"], row["braking_time"]
    if time is None:
        return f"not stopped: final joint speed {speed:.3g} rad/s"
    if speed == 0.0:
        steps = traj.n_steps - traj.brake_start
        return f"at rest after {time:.3f} s of braking ({steps} step{'s' * (steps != 1)})"
    return f"NOT at rest: final joint speed {speed:.3g} rad/s after {time:.3f} s of braking"


def write_text(path: Path, text: str) -> None:
    """Write ``text`` (UTF-8) atomically: a temporary file in the same folder, then renamed."""
    write_atomic(path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))
