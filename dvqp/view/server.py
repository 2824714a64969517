"""The interactive 3-D view in the browser, served by viser (the extra ``dvqp[view]``).

viser serves its own built three.js client (no network needed) and the scene over a
websocket. :class:`View` shows a :class:`~dvqp.view.scene3d.Scene3D`: the pipe and the
obstacles, the rail, the weld and the probe's path as lines, the arm (links at their margin
red) at the sample the time slider picks, and a ``play`` box that runs the samples in real
time. It listens on the address it is given (the command line's default: loopback only).
"""

from __future__ import annotations

import contextlib
import io
import math
import socket
import threading
import time
from collections.abc import Iterator

import numpy as np

from dvqp.errors import DvqpError
from dvqp.view.scene3d import COLORS, Scene3D

try:
    import viser

    AVAILABLE = True
except ImportError:  # the extra dvqp[view] is not installed
    AVAILABLE = False

MISSING = "the view needs viser: pip install 'dvqp[view]'"
LINK_THICKNESS = 0.02
"""m: the arm's links are drawn this thick."""
LINE_THICKNESS = 0.004
"""m: the rail, the weld and the path are drawn this thick."""
FRAME = 1.0 / 30.0
"""s: the least time between two poses while playing."""


@contextlib.contextmanager
def _quiet() -> Iterator[None]:
    """viser prints a banner when it starts and a line when it stops: only the URL is ours."""
    with contextlib.redirect_stdout(io.StringIO()):
        yield


def url(host: str, port: int) -> str:
    """The view's address (an IPv6 host in brackets)."""
    shown = f"[{host}]" if ":" in host and not host.startswith("[") else host
    return f"http://{shown}:{port}/"


class View:
    """A running view of ``view`` on ``host:port`` (port 0: any free one); :meth:`close`
    stops it.

    Raises
    ------
    DvqpError
        viser is not installed, or the address cannot be listened on.
    """

    def __init__(self, view: Scene3D, host: str, port: int) -> None:
        if not AVAILABLE:
            raise DvqpError(MISSING)
        port = _free(host, port)
        with _quiet():
            self.server = viser.ViserServer(host=host, port=port, label="dvqp view")
        if self.server.get_port() != port:  # taken meanwhile: viser moved on to another
            self.close()
            raise DvqpError(f"cannot listen on {host}:{port}: the port is in use")
        self.url, self.view = url(host, port), view
        self._stop = threading.Event()
        try:
            self._start()
        except BaseException:
            self.close()
            raise

    def _start(self) -> None:
        """The scene, the controls and the player."""
        view = self.view
        self._draw_scene()
        n = len(view.t) - 1
        gui = self.server.gui
        self.sample = gui.add_slider(
            "sample", min=0, max=max(n, 1), step=1, initial_value=n, disabled=n == 0
        )
        self.time = gui.add_text("t (s)", initial_value=f"{view.t[n]:.3f}", disabled=True)
        self.play = gui.add_checkbox("play", initial_value=False, disabled=n == 0)
        self.sample.on_update(lambda _: self.show(int(self.sample.value)))
        self.show(n)
        self._player = threading.Thread(target=self._run_player, daemon=True)
        self._player.start()

    def _draw_scene(self) -> None:
        """The pipe, the obstacles and the lines, and the camera outside the pipe facing the
        arm."""
        scene, view = self.server.scene, self.view
        scene.set_up_direction("+z")
        for m in view.meshes:
            faces = m.faces.astype(np.uint32)
            scene.add_mesh_simple(
                f"/{m.name}", m.vertices.astype(np.float32), faces, color=m.color, side="double"
            )
        for line in view.lines:
            scene.add_line_segments(
                f"/{line.name}",
                _segments(line.points),
                colors=_linear(line.color),
                thickness=LINE_THICKNESS,
            )
        chain = view.chain.reshape(-1, 3)
        centre = 0.5 * (chain.min(axis=0) + chain.max(axis=0))
        facing = math.atan2(float(chain[:, 1].sum()), float(chain[:, 0].sum()))
        out = 2.5 * view.pipe_radius + float(np.ptp(chain[:, 2]))
        camera = self.server.initial_camera
        camera.look_at = (0.0, 0.0, float(centre[2]))
        camera.position = (
            out * math.cos(facing),
            out * math.sin(facing),
            float(centre[2]) + 0.3 * out,
        )
        camera.up = (0.0, 0.0, 1.0)
        self.arm = scene.add_line_segments(
            "/arm",
            _segments(view.chain[-1]),
            colors=_linear(COLORS["arm"]),
            thickness=LINK_THICKNESS,
        )
        self.probe = scene.add_icosphere("/probe", radius=0.6 * LINK_THICKNESS, color=COLORS["arm"])

    def show(self, n: int) -> None:
        """Put the arm at sample ``n``: its links, red where at their margin, and the probe."""
        view = self.view
        colors = np.where(
            view.at_margin[n][:, None], _linear(COLORS["margin"]), _linear(COLORS["arm"])
        )
        self.arm.points = _segments(view.chain[n])
        self.arm.colors = np.repeat(colors[:, None, :], 2, axis=1).astype(np.uint8)
        self.probe.position = tuple(view.chain[n, -1])
        self.time.value = f"{view.t[n]:.3f}"

    def _run_player(self) -> None:
        """While ``play`` is ticked, move the slider on in real time, :data:`FRAME` apart (or
        to the next sample, if further), and after a pause at the last from the start again."""
        t, last = self.view.t, len(self.view.t) - 1
        while not self._stop.is_set():
            if not self.play.value or last == 0:
                self._stop.wait(0.05)
                continue
            n = int(self.sample.value)
            if n >= last:
                nxt, wait = 0, 0.5
            else:
                nxt = min(max(int(np.searchsorted(t, t[n] + FRAME)), n + 1), last)
                wait = max(float(t[nxt] - t[n]), 0.005)
            if not self._stop.wait(wait) and self.play.value:
                self.sample.value = nxt

    def close(self) -> None:
        """Stop the player and the server."""
        if hasattr(self, "_player"):
            self._stop.set()
            self._player.join(timeout=2.0)
        with _quiet():
            self.server.stop()


def _linear(color: tuple[int, int, int]) -> tuple[int, int, int]:
    """An sRGB colour as the linear one whose display is that colour (viser's lines take
    linear colours, its meshes sRGB)."""
    c = np.asarray(color, dtype=np.float64) / 255.0
    lin = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    r, g, b = (round(255.0 * float(v)) for v in lin)
    return r, g, b


def _segments(points: np.ndarray) -> np.ndarray:
    """A polyline's points (P, 3) as its segments (P − 1, 2, 3), float32."""
    p = np.asarray(points, dtype=np.float32)
    return np.stack([p[:-1], p[1:]], axis=1)


def _free(host: str, port: int) -> int:
    """``port`` (or, for 0, a free one) after checking it can be listened on at ``host``."""
    try:
        info = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)[0]
        with socket.socket(info[0], socket.SOCK_STREAM) as probe:
            probe.bind(info[4])
            return int(probe.getsockname()[1])
    except OSError as exc:
        raise DvqpError(f"cannot listen on {host}:{port}: {exc.strerror or exc}") from exc


def serve_forever(view: View, poll: float = 0.5) -> None:
    """Keep the view served until interrupted (Ctrl-C raises KeyboardInterrupt here)."""
    try:
        while True:
            time.sleep(poll)
    finally:
        view.close()
