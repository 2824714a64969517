"""The ``dvqp`` command line: ``plan``, ``compare``, ``plot``, ``backends``, ``bench``,
``console``, ``view``, ``cache`` and ``export-qps``.

Exit codes: 0 success (``compare`` and ``bench``: the comparison ran, whatever its runs'
verdicts; ``--check``: and every QP backend's run is ``ok``, the baseline's known limit
breaks aside); 1 a run failed (failed steps, a path's end not reached, a singular
configuration); 2 bad input (scene, backend, file names, an output that cannot be written),
reported as ``dvqp: <message>`` without a traceback and with nothing written; 130 interrupted
(Ctrl-C), 143 terminated (``SIGTERM``), nothing half-written or left behind. Warnings of the
numerical code are summed up in one line.
See ``docs/cli.md``.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import sys
from collections.abc import Sequence

from dvqp._files import output_path
from dvqp._versions import __version__, versions
from dvqp.cli import bench as bench_cmd
from dvqp.cli import cache as cache_cmd
from dvqp.cli import console as console_cli
from dvqp.cli import export as export_cmd
from dvqp.cli import plot_command, solver_option
from dvqp.cli import retime as retime_cli
from dvqp.cli import view as view_cli
from dvqp.cli.compiling import announced
from dvqp.cli.figures import FIGURE_FORMATS
from dvqp.cli.progress import (
    ProgressBar,
    check_size,
    interruptible,
    terminated,
    warnings_summed_up,
)
from dvqp.cli.report import (
    footer_lines,
    format_summary,
    format_table,
    rows_to_csv,
    write_text,
)
from dvqp.cli.solver_option import backend_list, solver_options
from dvqp.errors import DvqpError, SingularConfigurationError, one_line
from dvqp.motion.schedule import TIMINGS
from dvqp.resolution.registry import (
    PINV,
    check_name,
    default_resolvers,
    describe_resolvers,
)
from dvqp.run import comparison as cmp
from dvqp.run.planning import plan, scene_timing
from dvqp.scenes.scene import load_scene

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
    except KeyboardInterrupt as exc:  # Ctrl-C, or SIGTERM (Terminated)
        if terminated(exc):
            print("dvqp: terminated", file=sys.stderr)
            return 143
        print("dvqp: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # stdout piped into a reader that stopped early (``| head``)
        with contextlib.suppress(OSError, ValueError, AttributeError):
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1


def _run(args: argparse.Namespace) -> int:
    """Run the subcommand; a dvqp error is its one line on stderr and exit code 2."""
    try:
        with announced(getattr(args, "command", "")):
            return int(args.run(args))
    except DvqpError as exc:
        print(f"dvqp: {one_line(str(exc))}", file=sys.stderr)
        return 2


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="dvqp",
        description="Plan, compare and plot arm motions in a pipe's developed view.",
        epilog="exit codes: 0 success (compare, bench: they ran; --check: every run ok), 1 a run "
        "failed, 2 bad input (nothing written), 130 interrupted, 143 terminated",
    )
    parser.add_argument("--version", action="version", version=f"dvqp {__version__}")
    sub = parser.add_subparsers(title="commands", metavar="COMMAND", dest="command")
    p = sub.add_parser("plan", help="run a scene and save its trajectory")
    p.add_argument("scene", help="scene file (.toml)")
    p.add_argument("--backend", default="daqp", help="pinv or a QP backend (default: daqp)")
    p.add_argument(
        "-o",
        "--output",
        help="trajectory file to write (.npz or .csv; with "
        "--retime the retimed one: .npz, .csv or .json, a ROS JointTrajectory)",
    )
    p.add_argument(
        "--retime",
        action="store_true",
        help="retime the planned path: as fast as "
        "qd_max and qdd_max allow, at rest at both ends (needs dvqp[retime])",
    )
    p.add_argument("--rate", type=float, help="controller rate of --retime, Hz (default 500)")
    _timing_argument(p)
    solver_option.add_argument(p)
    p.set_defaults(run=_plan)
    c = sub.add_parser("compare", help="run scenes with several backends, print one table")
    c.add_argument("scenes", nargs="+", metavar="SCENE", help="scene files (.toml)")
    c.add_argument("--backends", help="comma-separated names (default: pinv + installed)")
    c.add_argument("--json", help="write the figures, machine and versions as JSON")
    c.add_argument("--csv", help="write the figures as CSV")
    c.add_argument("--plot", help="write a figure of the comparison (.png/.svg/.pdf)")
    c.add_argument("--jobs", type=_positive_int, default=1, help="worker processes (scenes)")
    c.add_argument(
        "--wide",
        action="store_true",
        help="every column in the table (default: the deciding figures, within 100 characters)",
    )
    c.add_argument(
        "--check",
        "--strict",
        dest="check",
        action="store_true",
        help="exit 1 unless every QP backend's run is ok (safe to send)",
    )
    _timing_argument(c)
    solver_option.add_argument(c)
    c.set_defaults(run=_compare)
    plot_command.register(sub)
    console_cli.register(sub)
    view_cli.register(sub)
    bench_cmd.register(sub)
    cache_cmd.register(sub)
    export_cmd.register(sub)
    b = sub.add_parser("backends", help="list the installed backends and their versions")
    b.set_defaults(run=_backends)
    return parser


def _timing_argument(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--timing",
        choices=TIMINGS,
        help="a path's timing: fixed (the paper's: "
        "the task relaxed where limits bind) or scaled (slow down along the "
        "path there); default: the scene's, else fixed",
    )


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be an integer >= 1, got {text!r}")
    return value


def _plan(args: argparse.Namespace) -> int:
    formats = retime_cli.FORMATS if args.retime else (".npz", ".csv")
    output = output_path(args.output, formats) if args.output is not None else None
    scene = load_scene(args.scene)
    rate = retime_cli.checked_rate(args.retime, args.rate)  # before any work, as the backend
    check_name(args.backend)  # unknown backend: exit 2 before any work
    scene_timing(scene, args.timing)  # nor a JOG scene asked to slow along a path
    options = solver_options(args.solver_option, [args.backend]).get(args.backend)
    check_size([scene], 1)
    try:  # a progress bar on stderr, erased when done
        with contextlib.closing(ProgressBar(sys.stderr)) as bar:
            traj = plan(
                scene,
                args.backend,
                progress=lambda k, n: bar.show(k, n, "steps"),
                options=options,
                tier=args.settings,
                timing=args.timing,
            )
    except SingularConfigurationError as exc:
        print(f"dvqp: {one_line(scene.source)}: {args.backend}: {exc}", file=sys.stderr)
        return 1
    if output is not None and rate is None:
        traj.save(output)  # written even for a failed run, to look at it
    row = cmp.summarize(scene, traj, args.settings)
    print(format_summary(scene, traj, row, None if rate is not None else output))
    if row["error"]:  # why check_run failed the run (with --retime: not retimed, not written)
        print(f"dvqp: {row['error']}", file=sys.stderr)
        return 1
    return 0 if rate is None else retime_cli.retimed(scene, traj, rate, output)


def _compare(args: argparse.Namespace) -> int:
    json_out = output_path(args.json, (".json",)) if args.json is not None else None
    csv_out = output_path(args.csv, (".csv",)) if args.csv is not None else None
    plot_out = output_path(args.plot, FIGURE_FORMATS) if args.plot is not None else None
    backends = [check_name(name) for name in backend_list(args.backends) or default_resolvers()]
    scenes = [load_scene(path) for path in args.scenes]  # every scene valid before any run
    options = solver_options(args.solver_option, backends)
    check_size(scenes, len(backends))
    with contextlib.closing(ProgressBar(sys.stderr)) as bar:
        rows = cmp.compare(
            args.scenes,
            backends,
            args.jobs,
            progress=bar.show,
            options=options,
            tier=args.settings,
            timing=args.timing,
        )
    if args.settings != "default":
        print(f"settings: {args.settings}")
    print(format_table(rows, wide=args.wide))
    for line in footer_lines(rows):
        print(line)
    if json_out is not None:  # no NaN in it: an undefined figure is null
        doc = {
            "backends": backends,
            "scenes": list(args.scenes),
            "settings": args.settings,
            "results": rows,
            "machine": cmp.machine(),
            "versions": versions(),
        }
        write_text(json_out, json.dumps(doc, indent=2, allow_nan=False) + "\n")
    if csv_out is not None:
        write_text(csv_out, rows_to_csv(rows))
    if plot_out is not None:
        from dvqp.cli.plot_compare import plot_comparison

        plot_comparison(rows, plot_out)
    qp_runs = [row for row in rows if row["backend"] != PINV]
    return 1 if args.check and not all(row["success"] for row in qp_runs) else 0


def _backends(args: argparse.Namespace) -> int:
    """Name, distribution, version and note of each resolver; the note of dvqp's own (a
    description) in parentheses, that of a QP backend (e.g. ``via qpsolvers 4.13.0``) as is."""
    for info in describe_resolvers():
        note = f"({info.note})" if info.note and info.distribution == "dvqp" else info.note
        print(f"{info.name:<22} {info.distribution} {info.version}" + (f" {note}" if note else ""))
    return 0
