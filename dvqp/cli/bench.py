"""``dvqp bench``: a seeded suite of random scenes run with every backend, here or on Dask.

:func:`register` adds the subcommand to the ``dvqp`` parser; :func:`run` runs it. Every
option is checked before anything runs or is written (exit 2, one line). Ctrl-C stops the
runs; the scenes finished before it are still summed up and written (``--json``, ``--csv``),
then the command ends as an interrupted one (exit 130). See ``docs/bench.md``.
"""

from __future__ import annotations

import argparse
import contextlib
import math
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from dvqp._files import output_folder, output_path
from dvqp.bench import (
    BenchInterrupted,
    DaskUnavailableError,
    PartialFile,
    Suite,
    bench_json,
    format_summary,
    import_distributed,
    rows_to_csv,
    run_suite,
    save_scenes,
)
from dvqp.bench.dask_run import SCENE_TIMEOUT, WorkersLostError
from dvqp.bench.execution import Where, generate_local
from dvqp.cli import solver_option
from dvqp.cli.progress import ProgressBar
from dvqp.cli.report import write_text
from dvqp.cli.solver_option import backend_list, solver_options
from dvqp.errors import DvqpError, ParameterError
from dvqp.resolution.registry import PINV, check_name, default_resolvers


@dataclass(frozen=True)
class Options:
    """The checked options of one ``dvqp bench``: ``backends`` known and without repeats,
    ``scheduler`` an address, ``"local"`` or None (run here), the files checked writable,
    ``scenes_dir`` an existing folder or one to create."""

    count: int
    seed: int
    backends: tuple[str, ...]
    workers: int
    scheduler: str | None
    scene_timeout: float
    json: Path | None
    csv: Path | None
    scenes_dir: Path | None
    solver_options: dict[str, dict[str, Any]]
    tier: str = "default"
    check: bool = False


def register(subparsers: Any) -> argparse.ArgumentParser:
    """Add the ``bench`` parser to ``subparsers`` (of ``dvqp``'s parser); return it."""
    p = subparsers.add_parser(
        "bench",
        help="run a seeded suite of random scenes with every backend",
        description="Generate random scenes (deterministic for a seed), run every backend on "
        "each, print a summary per backend (see docs/bench.md).",
    )
    p.add_argument("--count", default="24", help="number of scenes (default: 24)")
    p.add_argument("--seed", default="0", help="seed of the scenes, >= 0 (default: 0)")
    p.add_argument("--backends", help="comma-separated names (default: pinv + installed)")
    p.add_argument("--json", help="write results, summary, machine and versions as JSON")
    p.add_argument("--csv", help="write one row per scene and backend as CSV")
    p.add_argument("--save-scenes", metavar="DIR", help="write the scene files into DIR")
    p.add_argument(
        "--workers", default="1", help="local processes, or LocalCluster workers (default: 1)"
    )
    p.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="run on a Dask scheduler (tcp://host:8786), or 'local' for a LocalCluster",
    )
    p.add_argument(
        "--scene-timeout",
        metavar="SECONDS",
        default=str(SCENE_TIMEOUT),
        help=f"on Dask, give a scene up after running this long (default: {SCENE_TIMEOUT:g})",
    )
    solver_option.add_argument(p)
    p.add_argument(
        "--check",
        action="store_true",
        help="exit 1 unless every QP backend's run is ok (safe to send)",
    )
    p.set_defaults(run=run)
    return p


def run(args: argparse.Namespace) -> int:
    """Run ``dvqp bench``; return 0, or 1 when every Dask worker left (the finished scenes
    written) or, with ``--check``, a QP backend's run is not ok. Bad input raises a DvqpError
    before any run (exit 2); Ctrl-C a KeyboardInterrupt, after the finished scenes were summed
    up and written."""
    options = check_options(args)
    here = options.scheduler in (None, "local")  # else --workers is the cluster's business
    scenes = generate_local(options.seed, options.count, options.workers if here else 1)
    partial: list[PartialFile] = []

    def ready(where: Where) -> None:
        if options.scenes_dir is not None:
            options.scenes_dir.mkdir(exist_ok=True)
            save_scenes(scenes, options.scenes_dir)
        if out := options.json or options.csv:  # the results as they arrive, until written
            partial.append(PartialFile(out))

    try:
        with contextlib.closing(ProgressBar(sys.stderr)) as bar:
            suite = run_suite(
                scenes,
                options.backends,
                seed=options.seed,
                workers=options.workers,
                scheduler=options.scheduler,
                progress=bar.show,
                ready=ready,
                on_scene=lambda rows: [p.add(rows) for p in partial],
                scene_timeout=options.scene_timeout,
                options=options.solver_options,
                tier=options.tier,
            )
    except BenchInterrupted as exc:
        _report(exc.suite, options, partial)  # what finished is still written
        raise
    except WorkersLostError as exc:
        _report(exc.suite, options, partial)
        print(f"dvqp: scheduler {options.scheduler}: {exc}", file=sys.stderr)
        return 1
    _report(suite, options, partial)
    failed = [r for r in suite.rows if r["backend"] != PINV and not r["success"]]
    return 1 if options.check and failed else 0


def _report(suite: Suite, options: Options, partial: list[PartialFile]) -> None:
    """Print the summary; write the JSON and CSV files asked for, then remove the partial
    file that held the results while the suite ran."""
    print(format_summary(suite))
    if options.scenes_dir is not None:
        print(
            f"scene files     {options.scenes_dir}/bench-s{options.seed}-*.toml "
            f"({options.count}; 'dvqp plan FILE' runs one)"
        )
    if options.json is not None:
        write_text(options.json, bench_json(suite))
    if options.csv is not None:
        write_text(options.csv, rows_to_csv(suite))
    for file in partial:
        file.remove()


def check_options(args: argparse.Namespace) -> Options:
    """Every option checked, nothing run or written yet; else a DvqpError such as ``--count:
    must be an integer >= 1, got '0'``, an unknown backend, an output file that cannot be
    written, ``--scheduler needs Dask: pip install 'dvqp[dask]'``."""
    count = _integer("--count", args.count, 1)
    seed = _integer("--seed", args.seed, 0)
    workers = _integer("--workers", args.workers, 1)
    timeout = _seconds("--scene-timeout", args.scene_timeout)
    json_out = output_path(args.json, (".json",)) if args.json is not None else None
    csv_out = output_path(args.csv, (".csv",)) if args.csv is not None else None
    scenes_dir = _scenes_dir(args.save_scenes) if args.save_scenes is not None else None
    names = backend_list(args.backends)
    backends = tuple(dict.fromkeys(check_name(b) for b in names or default_resolvers()))
    if args.scheduler is not None:
        if not args.scheduler.strip():
            raise ParameterError("--scheduler", "expected an address or 'local'")
        try:
            import_distributed()
        except DaskUnavailableError as exc:
            raise DvqpError(f"--scheduler {exc}") from exc
    settings = solver_options(args.solver_option, backends)
    return Options(
        count,
        seed,
        backends,
        workers,
        args.scheduler,
        timeout,
        json_out,
        csv_out,
        scenes_dir,
        settings,
        args.settings,
        args.check,
    )


def _integer(option: str, text: str, minimum: int) -> int:
    """``text`` as an integer >= ``minimum``, else a ParameterError naming ``option``."""
    try:
        value = int(str(text).strip())
    except ValueError:
        value = None
    if value is None or value < minimum:
        raise ParameterError(option, f"must be an integer >= {minimum}, got {text!r}")
    return value


def _seconds(option: str, text: str) -> float:
    """``text`` as a finite number of seconds > 0, else a ParameterError naming ``option``."""
    try:
        value = float(str(text).strip())
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value > 0):
        raise ParameterError(option, f"must be a number of seconds > 0, got {text!r}")
    return value


def _scenes_dir(text: str) -> Path:
    """The ``--save-scenes`` folder (:func:`~dvqp._files.output_folder`): an existing folder
    that can be written in, or one to create in such a folder; as given."""
    output_folder(text, "--save-scenes")
    return Path(text)
