"""``dvqp export-qps SCENE --backend NAME -o DIR``: every QP of a run as a qpsolvers file.

See ``docs/qp-export.md`` (:mod:`dvqp.run.qp_export` writes it).
"""

from __future__ import annotations

import argparse
import contextlib
import sys
from collections import Counter
from pathlib import Path
from typing import Any

from dvqp.cli import solver_option
from dvqp.cli.progress import ProgressBar, check_size
from dvqp.cli.solver_option import solver_options
from dvqp.run.qp_export import INDEX, TEST_SET, export_folder, export_qps
from dvqp.scenes import load_scene


def register(subparsers: Any) -> None:
    """Add ``export-qps`` to ``subparsers`` (of ``dvqp``'s parser)."""
    e = subparsers.add_parser(
        "export-qps", help="write every QP of a run as a qpsolvers problem file, with dvqp's answer"
    )
    e.add_argument("scene", help="scene file (.toml)")
    e.add_argument("--backend", default="daqp", help="a QP backend (default: daqp)")
    e.add_argument(
        "-o",
        "--output",
        required=True,
        metavar="DIR",
        help="folder to write: new or empty (or --force)",
    )
    e.add_argument("--force", action="store_true", help="replace an earlier export in DIR")
    solver_option.add_argument(e)
    e.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Export the run's QPs; 0 once written, 1 if the run failed (written all the same)."""
    export_folder(args.output, args.force)  # before any work: the scene is read after it
    scene = load_scene(args.scene)
    options = solver_options(args.solver_option, [args.backend]).get(args.backend)
    check_size([scene], 1)
    with contextlib.closing(ProgressBar(sys.stderr)) as bar:
        exported = export_qps(
            scene,
            args.backend,
            args.output,
            options=options,
            tier=args.settings,
            force=args.force,
            progress=lambda k, n: bar.show(k, n, "steps"),
        )
    index = exported.index
    kinds = Counter(entry["kind"] for entry in index["problems"])
    counted = ", ".join(
        f"{kinds[kind]} {kind}" for kind in ("strict", "scaled", "relaxed") if kinds[kind]
    )
    print(
        f"wrote {len(index['problems'])} QPs ({counted or 'none'}) of {index['steps']} steps "
        f"to {_shown(args.output, exported.folder)} ({INDEX}, answers/, {TEST_SET})"
    )
    if index["error"]:
        print(f"dvqp: {index['error']}", file=sys.stderr)
        return 1
    return 0


def _shown(given: str, real: Path) -> str:
    """The folder as given, unless it goes through ``.`` or ``..`` (``qps/answers/..``):
    then where that leads, from the working folder if it is under it."""
    parts = given.replace("\\", "/").split("/")
    if "." not in parts[1:] and ".." not in parts:
        return given
    here = Path.cwd()
    return str(real.relative_to(here)) if real.is_relative_to(here) else str(real)
