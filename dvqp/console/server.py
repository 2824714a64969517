"""The console's web server (aiohttp, the optional extra ``dvqp[console]``; this module imports
without it, :data:`AVAILABLE`): the page and its files, the WebSocket of
:mod:`dvqp.console.protocol`, ``/trajectory.npz`` (what was driven since the last reset) and
``/stats.json`` (the clock's rate), each behind the checks of :mod:`dvqp.console.security`.
The arm steps while a WebSocket is open; see ``docs/console.md``.
"""

from __future__ import annotations

import asyncio
import re
import tempfile
from collections.abc import AsyncIterator, Callable
from pathlib import Path
from typing import Any

from dvqp.console import protocol, security
from dvqp.console.hub import Console
from dvqp.console.session import ConsoleSession
from dvqp.errors import DvqpError

try:
    from aiohttp import WSMsgType, web
except ImportError:  # the extra is not installed: dvqp console says what to install
    AVAILABLE = False
else:
    AVAILABLE = True

MISSING = "the console needs aiohttp: pip install 'dvqp[console]'"
"""The one-line error of ``dvqp console`` without the extra."""
STATIC = Path(__file__).with_name("static")
FILES = {
    "console.js": "text/javascript",
    "draw.js": "text/javascript",
    "panels.js": "text/javascript",
    "console.css": "text/css",
}
STATE_HZ = 50.0
"""State messages per second to each client."""
MAX_FRAME_BYTES = 1 << 20
"""A frame larger than this closes the connection (1009); one above
:data:`~dvqp.console.protocol.MAX_MESSAGE_BYTES` gets an ``error`` reply."""
HEARTBEAT = 2.0
"""Ping interval, s: a client that stops answering is dropped (and the arm stopped)."""


KEY: Any = web.AppKey("console", Console) if AVAILABLE else "console"


def create_app(console: Console) -> Any:
    """The aiohttp application of ``console`` (its clock starts and stops with the app)."""
    app = web.Application(middlewares=[_guard])
    app[KEY] = console
    app.router.add_get("/", _page)
    app.router.add_get("/ws", _websocket)
    app.router.add_get("/trajectory.npz", _trajectory)
    app.router.add_get("/stats.json", _stats)
    app.router.add_get("/{name}", _file)
    app.on_response_prepare.append(_headers)
    app.cleanup_ctx.append(_clock)
    app.on_shutdown.append(_close_sockets)
    return app


if AVAILABLE:

    @web.middleware
    async def _guard(request: web.Request, handler: Callable[..., Any]) -> Any:
        """Refuse a request without the token (401) or under a foreign Host (403)."""
        console = request.app[KEY]
        if not security.host_ok(request.headers.get("Host"), console.host):
            return web.Response(status=403, text="dvqp console: forbidden host\n")
        if not security.token_ok(request.query.get("token"), console.token):
            return web.Response(status=401, text="dvqp console: missing or wrong token\n")
        return await handler(request)


async def _headers(request: Any, response: Any) -> None:
    for name, value in security.HEADERS.items():
        response.headers.setdefault(name, value)


async def _clock(app: Any) -> AsyncIterator[None]:
    app[KEY].clock.start()
    yield
    app[KEY].clock.close()


async def _close_sockets(app: Any) -> None:
    for ws in list(app[KEY].sockets):
        await ws.close(code=1001, message=b"server shutdown")


async def _page(request: Any) -> Any:
    text = (STATIC / "index.html").read_text(encoding="utf-8")
    text = text.replace("{{token}}", request.app[KEY].token)
    return web.Response(text=text, content_type="text/html")


async def _file(request: Any) -> Any:
    name = request.match_info["name"]
    if name not in FILES:
        raise web.HTTPNotFound(text="dvqp console: not found\n")
    body = (STATIC / name).read_bytes()
    return web.Response(body=body, content_type=FILES[name], charset="utf-8")


async def _stats(request: Any) -> Any:
    console = request.app[KEY]
    return web.json_response(console.clock.stats.summary(console.clock.dt))


async def _trajectory(request: Any) -> Any:
    """What was driven, as ``.npz`` (written in a worker thread: compressing takes time)."""
    session = request.app[KEY].session
    body = await asyncio.get_running_loop().run_in_executor(None, _npz_bytes, session)
    name = re.sub(r"[^A-Za-z0-9._-]", "_", session.scene.name) or "scene"
    disposition = f'attachment; filename="{name}-console.npz"'
    return web.Response(
        body=body,
        content_type="application/octet-stream",
        headers={"Content-Disposition": disposition},
    )


def _npz_bytes(session: ConsoleSession) -> bytes:
    """The session's trajectory saved by :meth:`dvqp.Trajectory.save`, as bytes."""
    with tempfile.TemporaryDirectory(prefix="dvqp-console-") as folder:
        path = session.trajectory().save(Path(folder) / "console.npz")
        return path.read_bytes()


async def _websocket(request: Any) -> Any:
    """One client: the scene, then states; its messages applied or answered with an error."""
    console = request.app[KEY]
    if not security.origin_ok(request.headers.get("Origin"), request.headers.get("Host")):
        return web.Response(status=403, text="dvqp console: forbidden origin\n")
    ws = web.WebSocketResponse(heartbeat=HEARTBEAT, max_msg_size=MAX_FRAME_BYTES)
    await ws.prepare(request)
    console.connected(ws)
    sender = None
    try:
        await ws.send_str(console.scene_json)
        sender = asyncio.create_task(_send_states(console, ws))
        async for msg in ws:
            if msg.type in (WSMsgType.TEXT, WSMsgType.BINARY):
                reply = _reply(console, ws, msg.data)
                if reply is not None:
                    await ws.send_str(reply)
    except (ConnectionError, RuntimeError):
        pass  # the client went away
    finally:
        if sender is not None:
            sender.cancel()
        console.disconnected(ws)
    return ws


def _reply(console: Console, ws: Any, data: Any) -> str | None:
    """Apply a frame; whatever goes wrong is an ``error`` reply, never a dead server."""
    try:
        return console.handle(ws, data)
    except Exception as exc:  # a bug must not end the console
        return protocol.error(f"internal error: {type(exc).__name__}: {exc}")


async def _send_states(console: Console, ws: Any) -> None:
    """A ``state`` message every 1/:data:`STATE_HZ` s until the connection closes, and one
    as soon as a step was made with a new command (low latency from key to drawing)."""
    loop = asyncio.get_running_loop()
    period, deadline = 1.0 / STATE_HZ, loop.time()
    wake = asyncio.Event()
    console.wakers.add(wake)
    try:
        while not ws.closed:
            await ws.send_str(console.state_json())
            deadline = max(deadline + period, loop.time())
            try:
                await asyncio.wait_for(wake.wait(), timeout=deadline - loop.time())
            except asyncio.TimeoutError:
                continue
            wake.clear()
            await console.applied()
    except (ConnectionError, RuntimeError):
        pass
    finally:
        console.wakers.discard(wake)


async def serve(
    console: Console, port: int, announce: Callable[[str], None], ready: Any = None
) -> None:
    """Serve ``console`` on its host and ``port`` (0: any free port) until cancelled.

    ``announce`` gets the URL with the token once the server listens; ``ready`` (an
    :class:`asyncio.Future`, optional) gets the port.

    Raises
    ------
    DvqpError
        ``cannot listen on <host>:<port>: <reason>`` (a port in use, an unknown host).
    """
    if not AVAILABLE:
        raise DvqpError(MISSING)
    runner = web.AppRunner(create_app(console), access_log=None, handle_signals=False)
    await runner.setup()
    try:
        site = web.TCPSite(runner, console.host, port)
        try:
            await site.start()
        except OSError as exc:
            reason = exc.strerror or str(exc)
            raise DvqpError(f"cannot listen on {console.host}:{port}: {reason}") from None
        bound = runner.addresses[0][1] if runner.addresses else port
        announce(security.url(console.host, bound, console.token))
        if ready is not None:
            ready.set_result(bound)
        await asyncio.Event().wait()
    finally:
        await runner.cleanup()
