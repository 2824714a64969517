"""A console server run in a background thread for the console tests (no test of its own).

:class:`RunningConsole` serves a scene on 127.0.0.1 and a free port, in-process, so a test
can talk to it over HTTP and WebSocket and also look at its session and clock directly.
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import threading
from pathlib import Path
from typing import Any

import pytest

from dvqp import load_scene

ROOT = Path(__file__).resolve().parents[2]
PAPER = ROOT / "scenes" / "paper-two-inlets.toml"

aiohttp = pytest.importorskip(
    "aiohttp", reason="the console extra is not installed: pip install 'dvqp[console]'"
)

from dvqp.console import security  # noqa: E402
from dvqp.console.server import Console, serve  # noqa: E402
from dvqp.console.session import ConsoleSession  # noqa: E402


class RunningConsole:
    """The console of a scene served in a thread; :meth:`close` stops it.

    Attributes
    ----------
    console : Console
        The server's shared state (session, clock, token).
    port : int
        The port it listens on.
    """

    def __init__(self, scene: Path = PAPER, backend: str = "daqp") -> None:
        session = ConsoleSession(load_scene(scene), backend)
        self.console = Console(session, security.new_token())
        self.urls: list[str] = []
        self._ready: concurrent.futures.Future[int] = concurrent.futures.Future()
        self._thread = threading.Thread(target=self._run, name="console-test", daemon=True)
        self._thread.start()
        self.port = self._ready.result(timeout=30)

    def _run(self) -> None:
        loop = asyncio.new_event_loop()
        self._loop = loop
        try:
            loop.run_until_complete(self._serve())
        except asyncio.CancelledError:
            pass
        finally:
            loop.close()

    async def _serve(self) -> None:
        self._task = asyncio.current_task()
        ready = asyncio.get_running_loop().create_future()
        serving = asyncio.ensure_future(serve(self.console, 0, self.urls.append, ready))
        await asyncio.wait([ready, serving], return_when=asyncio.FIRST_COMPLETED)
        if serving.done():
            self._ready.set_exception(serving.exception() or RuntimeError("server ended"))
            return
        self._ready.set_result(ready.result())
        await serving

    @property
    def token(self) -> str:
        return self.console.token

    @property
    def base(self) -> str:
        return f"http://127.0.0.1:{self.port}"

    def url(self, path: str = "/", token: str | None = None) -> str:
        """``path`` on the server with the right token (or ``token``; "" for none)."""
        given = self.token if token is None else token
        return f"{self.base}{path}" + (f"?token={given}" if given else "")

    def close(self) -> None:
        self._loop.call_soon_threadsafe(self._task.cancel)  # type: ignore[union-attr]
        self._thread.join(timeout=10)


async def receive(ws: Any, kind: str, timeout: float = 5.0) -> dict[str, Any]:
    """The next message of type ``kind`` (others skipped)."""
    deadline = asyncio.get_running_loop().time() + timeout
    while True:
        left = deadline - asyncio.get_running_loop().time()
        message = await asyncio.wait_for(ws.receive_json(), timeout=max(left, 0.01))
        if message["type"] == kind:
            return message  # type: ignore[no-any-return]


async def latest_state(ws: Any, settle: float = 0.1) -> dict[str, Any]:
    """The last state received within ``settle`` s (at least one)."""
    state = await receive(ws, "state")
    loop = asyncio.get_running_loop()
    end = loop.time() + settle
    while loop.time() < end:
        try:
            message = await asyncio.wait_for(ws.receive_json(), timeout=end - loop.time())
        except asyncio.TimeoutError:
            break
        if message["type"] == "state":
            state = message
    return state
