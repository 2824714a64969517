"""What the server shares between requests: the session, its clock, the token, the clients."""

from __future__ import annotations

import asyncio
from typing import Any

from dvqp.console import protocol
from dvqp.console.clock import RealTimeClock
from dvqp.console.messages import scene_message
from dvqp.console.session import ConsoleSession


class Console:
    """Applies client messages, decides who holds the JOG, stops the arm when its connection
    goes and pauses the clock when no client is left. A connection is any hashable object."""

    def __init__(self, session: ConsoleSession, token: str, host: str = "127.0.0.1") -> None:
        self.session, self.token, self.host = session, token, host
        self.clock = RealTimeClock(session)
        self.sockets: set[Any] = set()
        self.wakers: set[asyncio.Event] = set()
        self.owner: Any = None
        self.scene_json = protocol.encode(scene_message(session.scene, session.backend))

    def connected(self, ws: Any) -> None:
        """A client is live: step in real time."""
        self.sockets.add(ws)
        self.clock.resume()

    def disconnected(self, ws: Any) -> None:
        """Stop the arm if its JOG came from ``ws``; halt it and pause when no client is left."""
        self.sockets.discard(ws)
        if not self.sockets:
            self.clock.pause()
            self.session.halt()
            self.owner = None
        elif self.owner is ws:
            self.session.stop()
            self.owner = None

    def handle(self, ws: Any, data: Any) -> str | None:
        """Apply one client message; the ``error`` reply if it is refused, else None."""
        try:
            message = protocol.parse(data)
        except protocol.ProtocolError as exc:
            return protocol.error(str(exc))
        if message.kind == "jog":
            self.session.jog(message.velocity)
        elif message.kind == "stop":
            self.session.stop()
        else:
            self.session.reset()
        self.owner = ws if message.kind == "jog" else None
        for wake in self.wakers:
            wake.set()
        return None

    async def applied(self) -> None:
        """Wait (at most 0.1 s) until a step was made with the latest command."""
        version, session = self.session.version, self.session
        for _ in range(100):
            if session.applied >= version or not self.clock.running:
                return
            await asyncio.sleep(0.001)

    def state_json(self) -> str:
        """The current ``state`` message, with the achieved real-time ratio."""
        state = self.session.snapshot()
        recent = self.clock.stats.recent(self.clock.dt)
        state["realtime"] = None if recent is None else round(recent, 4)
        return protocol.encode(state)
