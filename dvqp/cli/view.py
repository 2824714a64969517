"""``dvqp view TRAJ.npz | SCENE.toml``: the arm on the pipe in 3-D, in the browser.

:func:`run` serves on 127.0.0.1 (unless ``--host`` says otherwise: another address than the
loopback only with ``--insecure``, the view having no access token) until Ctrl-C and prints
one line, the URL. A trajectory is shown with its stored scene (or ``--scene``) and a time
slider; a scene file shows its start pose. Without the extra ``dvqp[view]`` it fails at once
(exit 2, ``dvqp: the view needs viser: pip install 'dvqp[view]'``).
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

import numpy as np

from dvqp.cli.console import _port
from dvqp.cli.plot_command import load_trajectory, scene_of, trajectory_3d
from dvqp.console.security import is_loopback
from dvqp.errors import DvqpError, one_line
from dvqp.scenes import load_scene
from dvqp.view.scene3d import Scene3D, scene_3d


def register(subparsers: Any) -> None:
    """Add the ``view`` subcommand to ``subparsers`` (its ``run`` is :func:`run`)."""
    v = subparsers.add_parser("view", help="the arm on the pipe in 3-D, in the browser")
    v.add_argument(
        "file",
        help="a trajectory (.npz) written by 'dvqp plan', or a scene file (.toml): its start pose",
    )
    v.add_argument(
        "--scene",
        help="with a trajectory: the scene file to read the arm from "
        "(default: the one stored in the trajectory)",
    )
    v.add_argument("--host", default="127.0.0.1", help="address to listen on (default: 127.0.0.1)")
    v.add_argument(
        "--insecure",
        action="store_true",
        help="serve on a --host that is not the loopback although the view has no access token "
        "(anyone who reaches the port sees the run)",
    )
    v.add_argument("--port", type=_port, default=8080, help="TCP port (default: 8080; 0: any)")
    v.set_defaults(run=run)


def view_of(args: argparse.Namespace) -> Scene3D:
    """The 3-D view of ``args.file``: a scene file's start pose, or a trajectory's run."""
    if args.file.lower().endswith(".toml"):
        if args.scene is not None:
            raise DvqpError("--scene goes with a trajectory, not a scene file")
        scene = load_scene(args.file)
        return scene_3d(scene, scene.q0[None], np.zeros(1), f"{scene.name}: start pose")
    traj = load_trajectory(args.file)
    return trajectory_3d(args.file, traj, scene_of(args.file, traj, args.scene))


def run(args: argparse.Namespace) -> int:
    """Serve the view of ``args.file`` until interrupted.

    The view has no access token (viser serves its own client): on an address that is not
    the loopback (:func:`dvqp.console.security.is_loopback`, the console's rule) it is served
    only with ``--insecure``, and a warning line says so on stderr.

    Raises a DvqpError (exit code 2) if the extra is missing, ``--host`` is not the loopback
    without ``--insecure``, the file is not a trajectory or a scene, or the port cannot be
    listened on.
    """
    from dvqp.view import server

    if not server.AVAILABLE:
        raise DvqpError(server.MISSING)
    exposed = not is_loopback(args.host)
    if exposed and not args.insecure:
        raise DvqpError(
            f"--host {one_line(args.host)}: not a loopback address, and the view has no access "
            "token: anyone who reaches it sees the run (add --insecure to serve it there "
            "anyway, on a network you trust)"
        )
    shown = server.View(view_of(args), args.host, args.port)
    if exposed:
        print(
            f"dvqp: warning: {shown.url} has no access token: anyone who reaches it sees the run",
            file=sys.stderr,
            flush=True,
        )
    print(shown.url, flush=True)
    server.serve_forever(shown)
    return 0
