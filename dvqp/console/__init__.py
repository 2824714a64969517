"""``dvqp console``: the operator's JOG console in the browser, live on the guarded QP step.

- :mod:`dvqp.console.session` — :class:`ConsoleSession`: a scene stepped with a held JOG
  command through the same verified step as ``dvqp plan``, recorded for "save";
- :mod:`dvqp.console.clock` — :class:`RealTimeClock`: steps it at the scene's ``dt``;
- :mod:`dvqp.console.protocol` — the WebSocket messages, checked and clamped;
- :mod:`dvqp.console.security` — token, Host and Origin checks;
- :mod:`dvqp.console.hub` — :class:`~dvqp.console.hub.Console`: the clients, who holds the JOG;
- :mod:`dvqp.console.server` — the aiohttp server (the extra ``dvqp[console]``) and the page
  in ``static/``.

See ``docs/console.md`` for the protocol and the security model.
"""

from dvqp.console.clock import RealTimeClock
from dvqp.console.session import ConsoleSession

__all__ = ["ConsoleSession", "RealTimeClock"]
