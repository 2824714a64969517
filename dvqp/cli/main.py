"""The ``dvqp`` command line: ``plan``, ``compare``, ``plot``, ``backends``, ``bench`` and
``console``.

Exit codes: 0 success (``compare`` and ``bench``: the comparison ran, whatever its runs'
verdicts; ``compare --strict``: and every run is ``ok``); 1 a run failed (failed steps, a
path's end not reached, a singular configuration); 2 bad input (scene, backend, file names, an
output that cannot be written), reported as ``dvqp: <message>`` without a traceback and with
nothing written; 130 interrupted (Ctrl-C), nothing half-written. Warnings of the numerical code
are summed up in one line.
See ``docs/cli.md``.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from dvqp import Trajectory, __version__, load_scene, plan
from dvqp import comparison as cmp
from dvqp._files import output_path
from dvqp._versions import versions
from dvqp.cli import bench as bench_cmd
from dvqp.cli import cache as cache_cmd
from dvqp.cli import console as console_cli
from dvqp.cli import solver_option
from dvqp.cli.figures import FIGURE_FORMATS
from dvqp.cli.progress import ProgressBar, check_size, interruptible, warnings_summed_up
from dvqp.cli.report import format_summary, format_table, rows_to_csv, write_text
from dvqp.cli.solver_option import solver_options
from dvqp.errors import DvqpError, SingularConfigurationError, one_line
from dvqp.resolution.registry import check_name, default_resolvers, describe_resolvers
from dvqp.scenes import environment, loads

__all__ = ["format_table", "main"]


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line with ``argv`` (default ``sys.argv[1:]``); return the exit code."""
    parser = _parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help, --version or a usage error (argparse printed it)
        return exc.code if isinstance(exc.code, int) else 2 if exc.code else 0
    if not hasattr(args, "run"):
        parser.print_help(sys.stderr)
        return 2
    try:
        with interruptible(), warnings_summed_up() as code:
            code.append(_run(args))
        return code[0]
    except KeyboardInterrupt:
        print("dvqp: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # stdout piped into a reader that stopped early (``| head``)
        with contextlib.suppress(OSError, ValueError, AttributeError):
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1


def _run(args: argparse.Namespace) -> int:
    """Run the subcommand; a dvqp error is its one line on stderr and exit code 2."""
    try:
        return int(args.run(args))
    except DvqpError as exc:
        print(f"dvqp: {one_line(str(exc))}", file=sys.stderr)
        return 2


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="dvqp",
        description="Plan, compare and plot arm motions in a pipe's developed view.",
        epilog="exit codes: 0 success (compare: it ran; --strict: every run ok), 1 a run "
        "failed, 2 bad input (nothing written), 130 interrupted",
    )
    parser.add_argument("--version", action="version", version=f"dvqp {__version__}")
    sub = parser.add_subparsers(title="commands", metavar="COMMAND")
    p = sub.add_parser("plan", help="run a scene and save its trajectory")
    p.add_argument("scene", help="scene file (.toml)")
    p.add_argument("--backend", default="daqp", help="pinv or a QP backend (default: daqp)")
    p.add_argument("-o", "--output", help="trajectory file to write (.npz or .csv)")
    solver_option.add_argument(p)
    p.set_defaults(run=_plan)
    c = sub.add_parser("compare", help="run scenes with several backends, print one table")
    c.add_argument("scenes", nargs="+", metavar="SCENE", help="scene files (.toml)")
    c.add_argument("--backends", help="comma-separated names (default: pinv + installed)")
    c.add_argument("--json", help="write the figures, machine and versions as JSON")
    c.add_argument("--csv", help="write the figures as CSV")
    c.add_argument("--plot", help="write a figure of the comparison (.png/.svg/.pdf)")
    c.add_argument("--jobs", type=_positive_int, default=1, help="worker processes (scenes)")
    c.add_argument("--strict", action="store_true",
                   help="exit 1 unless every run is ok (safe to send)")  # fmt: skip
    solver_option.add_argument(c)
    c.set_defaults(run=_compare)
    g = sub.add_parser("plot", help="draw a saved trajectory")
    g.add_argument("trajectory", help="trajectory file (.npz) written by 'dvqp plan'")
    g.add_argument("-o", "--output", required=True, help="figure (.png/.svg/.pdf, or .gif)")
    g.add_argument("--gif", action="store_true", help="write an animation (.gif)")
    g.add_argument("--full", action="store_true",
                   help="the developed view's whole circumference (default: where the arm and "
                        "the obstacles are)")  # fmt: skip
    g.add_argument("--limits", action="store_true",
                   help="write the limits page: each limit's quantity over time against its "
                        "bound")  # fmt: skip
    g.add_argument("--scene", help="with --limits: the scene file to read the arm and limits "
                                   "from (default: the one stored in the trajectory)")  # fmt: skip
    g.set_defaults(run=_plot)
    console_cli.register(sub)
    bench_cmd.register(sub)
    cache_cmd.register(sub)
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


def _notice(bar: ProgressBar, text: str) -> None:
    """While compiling, the bar says so; once done, a line says how long it took."""
    if text.startswith("compiled"):
        bar.note(text)
    else:
        bar.show(0, 1, text)


def _plan(args: argparse.Namespace) -> int:
    scene = load_scene(args.scene)
    output = output_path(args.output, (".npz", ".csv")) if args.output is not None else None
    check_name(args.backend)  # unknown backend: exit 2 before any work
    options = solver_options(args.solver_option, [args.backend]).get(args.backend)
    check_size([scene], 1)
    try:  # a progress bar on stderr, erased when done
        with contextlib.closing(ProgressBar(sys.stderr)) as bar:
            traj = plan(scene, args.backend, progress=lambda k, n: bar.show(k, n, "steps"),
                        notice=lambda text: _notice(bar, text), options=options)  # fmt: skip
    except SingularConfigurationError as exc:
        print(f"dvqp: {one_line(scene.source)}: {args.backend}: {exc}", file=sys.stderr)
        return 1
    if output is not None:
        traj.save(output)  # written even for a failed run, to look at it
    row = cmp.summarize(scene, traj)
    print(format_summary(scene, traj, row, output))
    if row["error"]:  # why check_run failed the run
        print(f"dvqp: {row['error']}", file=sys.stderr)
        return 1
    return 0


def _compare(args: argparse.Namespace) -> int:
    names = [b.strip() for b in args.backends.split(",")] if args.backends else None
    backends = [check_name(name) for name in names or default_resolvers()]
    scenes = [load_scene(path) for path in args.scenes]  # every scene valid before any run
    options = solver_options(args.solver_option, backends)
    check_size(scenes, len(backends))
    json_out = output_path(args.json, (".json",)) if args.json is not None else None
    csv_out = output_path(args.csv, (".csv",)) if args.csv is not None else None
    plot_out = output_path(args.plot, FIGURE_FORMATS) if args.plot is not None else None
    with contextlib.closing(ProgressBar(sys.stderr)) as bar:
        rows = cmp.compare(args.scenes, backends, args.jobs, progress=bar.show, options=options)
    print(format_table(rows))
    for row in rows:
        if row["error"]:
            print(f"  {row['scene']} / {row['backend']}: {row['error']}")
    if json_out is not None:  # no NaN in it: an undefined figure is null
        doc = {"backends": backends, "scenes": list(args.scenes), "results": rows,
               "machine": cmp.machine(), "versions": versions()}  # fmt: skip
        write_text(json_out, json.dumps(doc, indent=2, allow_nan=False) + "\n")
    if csv_out is not None:
        write_text(csv_out, rows_to_csv(rows))
    if plot_out is not None:
        from dvqp.cli.plot_compare import plot_comparison

        plot_comparison(rows, plot_out)
    return 1 if args.strict and not all(row["success"] for row in rows) else 0


def _plot(args: argparse.Namespace) -> int:
    traj = _load_trajectory(args.trajectory)
    if args.limits or args.scene is not None:
        return _plot_limits(args, traj)
    drawn_with: dict[str, Any] = {"full": args.full}
    if traj.scene_text:  # draw the stored scene's obstacles, levels and weld
        env = environment(traj.scene_text, f"{args.trajectory} (stored scene)")
        drawn_with |= {"obstacles": env.obstacles, "orbital_level": env.orbital_level,
                      "weld_z": env.weld, "min_height": env.min_height}  # fmt: skip
    from dvqp.cli import plot

    draw = plot.animate_trajectory if args.gif else plot.plot_trajectory
    print(f"wrote {draw(traj, args.output, **drawn_with)}")
    return 0


def _plot_limits(args: argparse.Namespace, traj: Trajectory) -> int:
    """The limits page of a trajectory, from its stored scene (or ``--scene``)."""
    if not args.limits or args.gif or args.full:
        raise DvqpError("--scene goes with --limits, which takes neither --gif nor --full")
    target = output_path(args.output, FIGURE_FORMATS)
    if args.scene is not None:
        scene = load_scene(args.scene)
    elif traj.scene_text:
        folder = Path(args.trajectory).parent  # a relative URDF: beside the trajectory
        scene = loads(traj.scene_text, f"{args.trajectory} (stored scene)", base_dir=folder)
    else:
        raise DvqpError(f"{args.trajectory}: no stored scene: give the run's --scene")
    from dvqp.cli.limit_series import limit_series
    from dvqp.cli.plot_limits import plot_limits

    try:
        page = limit_series(scene, traj)
    except DvqpError as exc:
        raise DvqpError(f"{args.trajectory}: not a run of {scene.source}: {exc}") from exc
    title = f"{scene.name} / {traj.backend or 'unknown resolver'}: limits over time"
    print(f"wrote {plot_limits(page, target, title)}")
    return 0


def _load_trajectory(path: str) -> Trajectory:
    """A trajectory file, checked enough to be drawn; else a DvqpError
    ``<path>: cannot read: <reason>`` or ``<path>: not a dvqp trajectory (<reason>)``."""
    try:
        with open(path, "rb") as fh:
            zipped = fh.read(4) == b"PK\x03\x04"
    except OSError as exc:
        raise DvqpError(f"{path}: cannot read: {exc.strerror or exc}") from exc
    if not zipped:
        raise DvqpError(f"{path}: not a dvqp trajectory (not an .npz file)")
    try:
        traj = Trajectory.load(path)
    except DvqpError as exc:  # dvqp reads arrays only, never pickled objects
        raise DvqpError(f"{path}: not a dvqp trajectory (not written by 'dvqp plan')") from exc
    if not _drawable(traj):
        raise DvqpError(f"{path}: not a dvqp trajectory (arrays of unexpected shapes)")
    return traj


def _drawable(traj: Trajectory) -> bool:
    """The arrays a plot reads are float arrays of consistent shapes."""
    t, q, qdot, tool, points = traj.t, traj.q, traj.qdot, traj.tool, traj.points
    low, holder = traj.link_height, traj.holder_height  # both, or neither (older files)
    arrays = (t, q, qdot, tool, points, traj.w, traj.min_clearance, low, holder)
    if not all(np.asarray(a).dtype.kind == "f" for a in arrays) or t.ndim != 1 or q.ndim != 2:
        return False
    n1 = t.shape[0]
    return (
        n1 >= 1 and q.shape[0] == n1 and qdot.shape == (n1 - 1, q.shape[1])
        and tool.shape == (n1, 4) and points.ndim == 3 and points.shape[0] == n1
        and points.shape[2] == 3 and traj.w.shape == (n1,) and traj.min_clearance.shape == (n1,)
        and low.shape == holder.shape in ((n1,), (0,))
    )  # fmt: skip


def _backends(args: argparse.Namespace) -> int:
    """Name, distribution, version and note of each resolver; the note of dvqp's own (a
    description) in parentheses, that of a QP backend (e.g. ``via qpsolvers 4.13.0``) as is."""
    for info in describe_resolvers():
        note = f"({info.note})" if info.note and info.distribution == "dvqp" else info.note
        print(f"{info.name:<22} {info.distribution} {info.version}" + (f" {note}" if note else ""))
    return 0
