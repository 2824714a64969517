"""The ``dvqp`` command line: ``plan``, ``compare``, ``plot`` and ``backends``.

Exit codes: 0 success; 1 a run failed (failed steps, a path's end not reached, a singular
configuration); 2 bad input (scene, backend, file names), reported as ``dvqp: <message>``
without a traceback and with nothing written. See ``docs/cli.md``.
"""

from __future__ import annotations

import argparse
import contextlib
import csv
import io
import json
import os
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any, TextIO

from dvqp.cli import compare as cmp
from dvqp import planning
from dvqp._files import atomic_file, output_path
from dvqp.errors import BackendError, DvqpError, SingularConfigurationError
from dvqp.scenes.scene import environment, load_scene
from dvqp.motion.trajectory import Trajectory

TABLE = (  # (row key, header, format)
    ("scene", "scene", "{}"), ("backend", "backend", "{}"), ("success", "ok", "{}"),
    ("steps", "steps", "{}"), ("median_step_us", "med us", "{:.0f}"),
    ("p95_step_us", "p95 us", "{:.0f}"), ("ratio_to_pinv", "x pinv", "{:.2f}"),
    ("max_task_error", "task err", "{:.1e}"), ("min_clearance", "clearance m", "{:+.4f}"),
    ("max_joint_limit_violation", "q viol rad", "{:.3g}"),
    ("max_velocity_limit_violation", "qd viol rad/s", "{:.3g}"), ("failures", "fails", "{}"),
)  # fmt: skip


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line with ``argv`` (default ``sys.argv[1:]``); return the exit code."""
    parser = _parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help or a usage error (argparse printed it)
        return int(exc.code or 0)
    if not hasattr(args, "run"):
        parser.print_help(sys.stderr)
        return 2
    try:
        return int(args.run(args))
    except DvqpError as exc:
        print(f"dvqp: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # stdout piped into a reader that stopped early (``| head``)
        with contextlib.suppress(OSError, ValueError, AttributeError):
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="dvqp",
        description="Plan, compare and plot arm motions in a pipe's developed view.",
        epilog="exit codes: 0 success, 1 a run failed, 2 bad input (nothing written)",
    )
    sub = parser.add_subparsers(title="commands", metavar="COMMAND")
    p = sub.add_parser("plan", help="run a scene and save its trajectory")
    p.add_argument("scene", help="scene file (.toml)")
    p.add_argument("--backend", default="daqp", help="pinv or a QP backend (default: daqp)")
    p.add_argument("-o", "--output", help="trajectory file to write (.npz or .csv)")
    p.set_defaults(run=_plan)
    c = sub.add_parser("compare", help="run scenes with several backends, print one table")
    c.add_argument("scenes", nargs="+", metavar="SCENE", help="scene files (.toml)")
    c.add_argument("--backends", help="comma-separated names (default: pinv + installed)")
    c.add_argument("--json", help="write the figures, machine and versions as JSON")
    c.add_argument("--csv", help="write the figures as CSV")
    c.add_argument("--plot", help="write a figure of the comparison (.png/.svg/.pdf)")
    c.add_argument("--jobs", type=_positive_int, default=1, help="worker processes (scenes)")
    c.set_defaults(run=_compare)
    g = sub.add_parser("plot", help="draw a saved trajectory")
    g.add_argument("trajectory", help="trajectory file (.npz) written by 'dvqp plan'")
    g.add_argument("-o", "--output", required=True, help="figure (.png/.svg/.pdf, or .gif)")
    g.add_argument("--gif", action="store_true", help="write an animation (.gif)")
    g.set_defaults(run=_plot)
    b = sub.add_parser("backends", help="list the installed backends and their versions")
    b.set_defaults(run=_backends)
    return parser


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be an integer >= 1, got {text!r}")
    return value


# -- commands ---------------------------------------------------------------------------------


def _plan(args: argparse.Namespace) -> int:
    scene = load_scene(args.scene)
    output = output_path(args.output, (".npz", ".csv")) if args.output else None
    planning.make_resolver(scene, args.backend)  # unknown backend: exit 2 before any work
    bar = _Bar(sys.stderr)
    try:
        traj = planning.plan(scene, args.backend, progress=lambda k, n: bar.show(k, n, "steps"))
    except SingularConfigurationError as exc:
        bar.close()
        print(f"dvqp: {scene.source}: {args.backend}: {exc}", file=sys.stderr)
        return 1
    bar.close()
    if output is not None:
        traj.save(output)  # written even for a failed run, to look at it
    row = cmp.summarize(scene, traj)
    print(_summary(scene, traj, row, output))
    why = planning.failure(scene, traj)
    if why is not None:
        print(f"dvqp: {why}", file=sys.stderr)
        return 1
    return 0


def _compare(args: argparse.Namespace) -> int:
    names = [b.strip() for b in args.backends.split(",")] if args.backends else None
    backends = names or planning.default_backends()
    known = planning.available_backends()
    for name in backends:
        if name not in known:
            raise BackendError(f"unknown backend {name!r}; installed: {', '.join(known)}")
    for path in args.scenes:
        load_scene(path)  # every scene valid before any run
    json_out = output_path(args.json, (".json",)) if args.json else None
    csv_out = output_path(args.csv, (".csv",)) if args.csv else None
    plot_out = output_path(args.plot, (".png", ".svg", ".pdf")) if args.plot else None
    bar = _Bar(sys.stderr)
    try:
        rows = cmp.compare(args.scenes, backends, args.jobs, progress=bar.show)
    finally:
        bar.close()
    print(format_table(rows))
    for row in rows:
        if row["error"]:
            print(f"  {row['scene']} / {row['backend']}: {row['error']}")
    if json_out is not None:
        doc = {"backends": list(backends), "scenes": list(args.scenes), "results": rows,
               "machine": cmp.machine(), "versions": cmp.versions()}  # fmt: skip
        _write(json_out, json.dumps(doc, indent=2, allow_nan=False) + "\n")
    if csv_out is not None:
        _write(csv_out, _csv(rows))
    if plot_out is not None:
        from dvqp.cli.plot_compare import plot_comparison

        plot_comparison(rows, plot_out)
    return 0 if all(row["success"] for row in rows) else 1


def _plot(args: argparse.Namespace) -> int:
    traj = Trajectory.load(args.trajectory)
    env = (
        environment(traj.scene_text, f"{args.trajectory} (stored scene)")
        if traj.scene_text
        else None
    )
    try:
        from dvqp.cli import plot
    except ImportError as exc:  # pragma: no cover - dvqp.cli.plot ships with dvqp
        raise DvqpError(f"plotting is not available: {exc}") from exc
    draw = plot.animate_trajectory if args.gif else plot.plot_trajectory
    kw: dict[str, Any] = {}
    if env is not None:
        kw = {"obstacles": env.obstacles, "orbital_level": env.orbital_level, "weld_z": env.weld}
    written = draw(traj, args.output, **kw)
    print(f"wrote {written}")
    return 0


def _backends(args: argparse.Namespace) -> int:
    import solvers
    from dvqp import __version__
    from solvers.registry import DIRECT, DISTRIBUTIONS, QPSOLVERS_PREFIX

    found = solvers.backend_versions()
    print(f"{planning.PINV:<22} dvqp {__version__} (pseudoinverse baseline, paper eq. 18)")
    for name in solvers.available_backends():
        solver = name.removeprefix(QPSOLVERS_PREFIX)
        dist = DISTRIBUTIONS.get(solver, solver)
        via = "" if name in DIRECT else f" via qpsolvers {found.get('qpsolvers', '?')}"
        print(f"{name:<22} {dist} {found.get(dist, '?')}{via}")
    return 0


# -- output -----------------------------------------------------------------------------------


def format_table(rows: Sequence[dict[str, Any]]) -> str:
    """The comparison as an aligned text table (``-``: undefined)."""

    def cell(row: dict[str, Any], key: str, fmt: str) -> str:
        value = row.get(key)
        if value is None:
            return "-"
        if isinstance(value, bool):
            return "yes" if value else "NO"
        return fmt.format(value)

    table = [[h for _, h, _ in TABLE]] + [[cell(r, k, f) for k, _, f in TABLE] for r in rows]
    widths = [max(len(line[i]) for line in table) for i in range(len(TABLE))]
    just = [str.ljust, str.ljust] + [str.rjust] * (len(TABLE) - 2)
    lines = [
        "  ".join(j(c, w) for j, c, w in zip(just, line, widths, strict=True)) for line in table
    ]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)


def _summary(scene: Any, traj: Trajectory, row: dict[str, Any], output: Path | None) -> str:
    fails = row["failures"]
    tool = traj.dv[-1]
    lines = [
        f"scene           {scene.name} ({scene.source}), {scene.mode} mode",
        f"backend         {traj.backend}",
        f"steps           {traj.n_steps}, " + ("all succeeded" if not fails else f"{fails} failed"),
        f"max task error  {_num(row['max_task_error'], '{:.2e}')}",
        f"min clearance   {_num(row['min_clearance'], '{:+.4f} m')}",
        f"step time       median {_num(row['median_step_us'], '{:.0f}')} us, "
        f"p95 {_num(row['p95_step_us'], '{:.0f}')} us",
        f"final tool DV   l = {tool[0]:.4f} m, z = {tool[1]:.4f} m, h = {tool[2]:.4f} m, "
        f"alpha = {tool[3]:.4f} rad",
    ]
    if row["final_tracking_error"] is not None:
        lines.append(f"final tracking  {row['final_tracking_error'] * 1e3:.3g} mm")
    if output is not None:
        lines.append(f"saved           {output}")
    return "\n".join(lines)


def _num(value: float | None, fmt: str) -> str:
    return "-" if value is None else fmt.format(value)


def _csv(rows: Sequence[dict[str, Any]]) -> str:
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(cmp.FIELDS)
    for row in rows:
        out = []
        for key in cmp.FIELDS:
            value = row.get(key)
            out.append(
                "" if value is None else str(value).lower() if isinstance(value, bool) else value
            )
        writer.writerow(out)
    return buf.getvalue()


def _write(path: Path, text: str) -> None:
    """Write ``text`` atomically: a temporary file in the same folder, then renamed."""
    with atomic_file(path) as tmp:
        tmp.write_text(text, encoding="utf-8")


class _Bar:
    """A one-line progress bar on a terminal (silent when the stream is not a TTY)."""

    def __init__(self, stream: TextIO, width: int = 30) -> None:
        self.stream, self.width = stream, width
        self.enabled = bool(getattr(stream, "isatty", lambda: False)())
        self._last = -1

    def show(self, done: int, total: int, label: str = "") -> None:
        """Draw ``done`` of ``total`` (redrawn at most every 1 %)."""
        if not self.enabled or total <= 0:
            return
        percent = 100 * done // total
        if percent == self._last and done != total:
            return
        self._last = percent
        filled = self.width * done // total
        bar = "#" * filled + "." * (self.width - filled)
        self.stream.write(f"\r[{bar}] {done}/{total} {label[:40]:<40}")
        self.stream.flush()

    def close(self) -> None:
        """Erase the bar."""
        if self.enabled and self._last >= 0:
            self.stream.write("\r" + " " * (self.width + 60) + "\r")
            self.stream.flush()
