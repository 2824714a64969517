"""``dvqp plot TRAJ.npz -o FIG [--gif] [--full] [--limits | --3d [--scene SCENE]]``: draw a
saved run.

The trajectory file is checked enough to be drawn before anything is drawn; the figure modules
(matplotlib) are imported only here, when a figure is asked for.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

import numpy as np

from dvqp._files import output_path
from dvqp._inputs import NpzArrays
from dvqp.cli.figures import FIGURE_FORMATS
from dvqp.errors import DvqpError, InputFileError, one_line
from dvqp.motion.trajectory import Trajectory
from dvqp.scenes import Scene, environment, load_scene, loads
from dvqp.view.scene3d import Scene3D, scene_3d


def register(subparsers: Any) -> None:
    """Add ``plot`` to ``subparsers`` (of ``dvqp``'s parser)."""
    g = subparsers.add_parser("plot", help="draw a saved trajectory")
    g.add_argument("trajectory", help="trajectory file (.npz) written by 'dvqp plan'")
    g.add_argument("-o", "--output", required=True, help="figure (.png/.svg/.pdf, or .gif)")
    g.add_argument("--gif", action="store_true", help="write an animation (.gif)")
    g.add_argument(
        "--full",
        action="store_true",
        help="the developed view's whole circumference (default: where the arm and "
        "the obstacles are)",
    )
    g.add_argument(
        "--limits",
        action="store_true",
        help="write the limits page: each limit's quantity over time against its bound",
    )
    g.add_argument(
        "--3d",
        dest="three_d",
        action="store_true",
        help="write a still of the 3-D view: the pipe, its obstacles as the objects "
        "they stand for, the arm at the first and last sample",
    )
    g.add_argument(
        "--scene",
        help="with --limits or --3d: the scene file to read the arm "
        "and limits from (default: the one stored in the trajectory)",
    )
    g.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Draw a saved trajectory (or its limits page, or its 3-D still); 0 once written. The
    options and the output are checked before the trajectory is read."""
    _check_options(args)
    target = output_path(args.output, (".gif",) if args.gif else FIGURE_FORMATS)
    traj = load_trajectory(args.trajectory)
    if args.three_d:
        return _plot_3d(args, traj, target)
    if args.limits:
        return _plot_limits(args, traj, target)
    drawn_with: dict[str, Any] = {"full": args.full}
    if traj.scene_text:  # draw the stored scene's obstacles, levels and weld
        env = environment(traj.scene_text, f"{args.trajectory} (stored scene)")
        drawn_with |= {
            "obstacles": env.obstacles,
            "orbital_level": env.orbital_level,
            "weld_z": env.weld,
            "min_height": env.min_height,
        }
    from dvqp.cli import plot

    draw = plot.animate_trajectory if args.gif else plot.plot_trajectory
    print(f"wrote {draw(traj, target, **drawn_with)}")
    return 0


def _check_options(args: argparse.Namespace) -> None:
    """Refuse options that do not go together (a DvqpError)."""
    if args.three_d:
        if args.limits or args.gif or args.full:
            raise DvqpError("--3d takes neither --limits, --gif nor --full")
    elif (args.limits or args.scene is not None) and (not args.limits or args.gif or args.full):
        raise DvqpError(
            "--scene goes with --limits or --3d; --limits takes neither --gif nor --full"
        )


def _plot_limits(args: argparse.Namespace, traj: Trajectory, target: Path) -> int:
    """The limits page of a trajectory, from its stored scene (or ``--scene``)."""
    scene = scene_of(args.trajectory, traj, args.scene)
    from dvqp.cli.limit_series import limit_series
    from dvqp.cli.plot_limits import plot_limits

    try:
        page = limit_series(scene, traj)
    except DvqpError as exc:
        raise DvqpError(f"{args.trajectory}: not a run of {scene.source}: {exc}") from exc
    title = f"{scene.name} / {traj.backend or 'unknown resolver'}: limits over time"
    print(f"wrote {plot_limits(page, target, title)}")
    _note_other_scene(args, traj, scene)
    return 0


def _plot_3d(args: argparse.Namespace, traj: Trajectory, target: Path) -> int:
    """The still of the 3-D view of a trajectory, with its stored scene (or ``--scene``)."""
    scene = scene_of(args.trajectory, traj, args.scene)
    view = trajectory_3d(args.trajectory, traj, scene)
    from dvqp.cli.plot3d import plot_3d

    print(f"wrote {plot_3d(view, target)}")
    _note_other_scene(args, traj, scene)
    return 0


def _note_other_scene(args: argparse.Namespace, traj: Trajectory, scene: Scene) -> None:
    """Say on stderr that ``--scene`` is not the scene text stored in the trajectory (allowed:
    to see a run against other limits, say)."""
    if args.scene is not None and traj.scene_text and traj.scene_text != scene.text:
        print(
            f"dvqp: note: {one_line(args.trajectory)} was planned from another scene text "
            f"than {one_line(args.scene)}: drawn with the latter's arm, obstacles and limits",
            file=sys.stderr,
        )


def scene_of(path: str, traj: Trajectory, scene_file: str | None) -> Scene:
    """The scene of the trajectory read from ``path``: ``scene_file`` if given, else the one
    stored in it (a relative URDF read beside the trajectory); a DvqpError without either."""
    if scene_file is not None:
        return load_scene(scene_file)
    if not traj.scene_text:
        raise DvqpError(f"{path}: no stored scene: give the run's --scene")
    return loads(traj.scene_text, f"{path} (stored scene)", base_dir=Path(path).parent)


def trajectory_3d(path: str, traj: Trajectory, scene: Scene, samples: int = 2000) -> Scene3D:
    """The 3-D view of a run of ``scene`` (read from ``path``) at no more than ``samples``
    evenly spaced samples, the last one included; a DvqpError if it is not a run of it."""
    if traj.q.shape[1] != scene.robot.n:
        raise DvqpError(
            f"{path}: not a run of {scene.source}: {traj.q.shape[1]} joints, "
            f"the scene's arm has {scene.robot.n}"
        )
    if traj.pipe_radius and abs(traj.pipe_radius - scene.pipe_radius) > 1e-12:
        raise DvqpError(
            f"{path}: not a run of {scene.source}: its pipe radius is "
            f"{traj.pipe_radius:g} m, the scene's {scene.pipe_radius:g} m"
        )
    pick = np.unique(np.linspace(0, len(traj.t) - 1, min(samples, len(traj.t))).round())
    pick = pick.astype(np.int64)
    title = f"{scene.name} / {traj.backend or 'unknown resolver'}"
    return scene_3d(scene, traj.q[pick], traj.t[pick], title)


def load_trajectory(path: str) -> Trajectory:
    """A trajectory file, checked enough to be drawn (its arrays' declared sizes before any
    is inflated: :meth:`~dvqp.motion.trajectory.Trajectory.load`).

    Raises
    ------
    InputFileError
        ``<path>: cannot read: <reason>``, ``<path>: not a dvqp trajectory (<reason>)``, or a
        retimed motion (``dvqp plan --retime``), which is not drawn.
    """
    try:
        with open(path, "rb") as fh:
            zipped = fh.read(4) == b"PK\x03\x04"
    except (OSError, ValueError) as exc:
        raise InputFileError(path, f"cannot read: {getattr(exc, 'strerror', None) or exc}") from exc
    if not zipped:
        raise InputFileError(path, "not a dvqp trajectory (not an .npz file)")
    try:
        traj = Trajectory.load(path)
    except InputFileError as exc:
        if _retimed(path):
            raise InputFileError(
                path,
                "a retimed motion (dvqp plan --retime): dvqp plot draws planned runs; save the "
                "run itself (dvqp plan SCENE -o RUN.npz) and plot that",
            ) from exc
        raise
    if not _drawable(traj):
        raise InputFileError(path, "not a dvqp trajectory (arrays of unexpected shapes)")
    return traj


def _retimed(path: str) -> bool:
    """The file is a retimed motion's (:meth:`dvqp.retime.Retimed.save`)."""
    try:
        with NpzArrays(path, "a retimed motion") as npz:
            return {"rate", "planned_duration", "qddot"} <= set(npz.members)
    except InputFileError:
        return False


def _drawable(traj: Trajectory) -> bool:
    """The arrays a plot reads are float arrays of consistent shapes."""
    t, q, qdot, tool, points = traj.t, traj.q, traj.qdot, traj.tool, traj.points
    low, holder = traj.link_height, traj.holder_height  # both, or neither (older files)
    arrays = (t, q, qdot, tool, points, traj.w, traj.min_clearance, low, holder)
    if not all(np.asarray(a).dtype.kind == "f" for a in arrays) or t.ndim != 1 or q.ndim != 2:
        return False
    n1 = t.shape[0]
    return (
        n1 >= 1
        and q.shape[0] == n1
        and qdot.shape == (n1 - 1, q.shape[1])
        and tool.shape == (n1, 4)
        and points.ndim == 3
        and points.shape[0] == n1
        and points.shape[2] == 3
        and traj.w.shape == (n1,)
        and traj.min_clearance.shape == (n1,)
        and low.shape == holder.shape in ((n1,), (0,))
    )
