"""``dvqp console``: the operator's JOG console in the browser, live on the guarded QP step.

:mod:`~dvqp.console.session` steps a scene with a held JOG command through the same verified
step as ``dvqp plan``, :mod:`~dvqp.console.clock` at the scene's ``dt``;
:mod:`~dvqp.console.server` (aiohttp, the extra ``dvqp[console]``) serves the page in
``static/`` and the WebSocket. See ``docs/console.md`` for the protocol and the security model.
"""

from dvqp.console.clock import RealTimeClock
from dvqp.console.session import ConsoleSession

__all__ = ["ConsoleSession", "RealTimeClock"]
