"""``dvqp console SCENE``: drive the arm live from the browser (see ``docs/console.md``).

:func:`run` serves on 127.0.0.1 (unless ``--host`` says otherwise) until Ctrl-C and prints
one line, the URL with a fresh random token. Without the extra ``dvqp[console]`` it fails at
once (exit 2, ``dvqp: the console needs aiohttp: pip install 'dvqp[console]'``).
"""

from __future__ import annotations

import argparse
import asyncio
import gc
from typing import Any

from dvqp.errors import DvqpError
from dvqp.resolution.registry import check_name
from dvqp.scenes import load_scene


def register(subparsers: Any) -> None:
    """Add the ``console`` subcommand to ``subparsers`` (its ``run`` is :func:`run`)."""
    c = subparsers.add_parser("console", help="drive the arm live in the browser (JOG console)")
    c.add_argument("scene", help="scene file (.toml): arm, start, obstacles, limits, dt")
    c.add_argument("--backend", default="daqp", help="pinv or a QP backend (default: daqp)")
    c.add_argument("--host", default="127.0.0.1", help="address to listen on (default: 127.0.0.1)")
    c.add_argument("--port", type=_port, default=8765, help="TCP port (default: 8765; 0: any)")
    c.set_defaults(run=run)


def _port(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = -1
    if not 0 <= value <= 65535:
        raise argparse.ArgumentTypeError(f"must be an integer in [0, 65535], got {text!r}")
    return value


def run(args: argparse.Namespace) -> int:
    """Serve the console of ``args.scene`` until interrupted; 0 when the server ends.

    Raises a DvqpError (exit code 2) if the extra is missing, the scene is invalid, the
    backend unknown, or the port cannot be listened on.
    """
    from dvqp.console import server

    if not server.AVAILABLE:
        raise DvqpError(server.MISSING)
    scene = load_scene(args.scene)
    backend = check_name(args.backend)
    from dvqp.console.session import ConsoleSession

    console = server.Console(ConsoleSession(scene, backend), server.security.new_token(), args.host)
    gc.freeze()  # the scene, the arm and the libraries: never scanned again, no 60 ms GC pauses

    try:
        asyncio.run(server.serve(console, args.port, lambda url: print(url, flush=True)))
    finally:
        console.clock.close()
    return 0
