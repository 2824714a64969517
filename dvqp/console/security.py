"""Who may talk to the console: the token, the Host header and the WebSocket Origin.

Pure functions on strings (no web framework), used by :mod:`dvqp.console.server`:

- every request carries ``?token=<token>``, compared in constant time (else 401);
- a console bound to a loopback address answers only requests whose ``Host`` names a loopback
  address (``127.x.x.x``, ``localhost``, ``[::1]``), against DNS rebinding (else 403);
- a WebSocket request with an ``Origin`` header is accepted only from the console's own
  origin (the ``Host`` it was asked under), so another site open in the same browser cannot
  drive the arm (else 403); one without ``Origin`` (a pendant, a ROS bridge) needs the token
  only.
"""

from __future__ import annotations

import hmac
import ipaddress
import secrets
from urllib.parse import urlsplit

TOKEN_BYTES = 32
"""Random bytes of a new token (``secrets.token_urlsafe``: 43 characters)."""

HEADERS = {
    "Content-Security-Policy": (
        "default-src 'none'; script-src 'self'; style-src 'self'; img-src 'self' data:; "
        "connect-src 'self'; frame-ancestors 'none'; base-uri 'none'; form-action 'none'"
    ),
    "Referrer-Policy": "no-referrer",
    "X-Content-Type-Options": "nosniff",
    "X-Frame-Options": "DENY",
    "Cache-Control": "no-store",
}
"""Headers of every HTTP response: nothing but the console's own scripts runs in the page,
the token never leaks in a Referer, nothing is cached, the page is never framed."""


def new_token() -> str:
    """A fresh random access token."""
    return secrets.token_urlsafe(TOKEN_BYTES)


def token_ok(given: str | None, token: str) -> bool:
    """``given`` is the token (constant-time comparison)."""
    if not given:
        return False
    return hmac.compare_digest(given.encode("utf-8", "replace"), token.encode("utf-8"))


def hostname(host: str | None) -> str | None:
    """The host name of a ``Host`` header or bind address, lower case, no brackets or port."""
    if not host:
        return None
    try:
        name = urlsplit("//" + host).hostname
    except ValueError:
        return None
    return name.lower() if name else None


def is_loopback(name: str | None) -> bool:
    """A host name or address (no port; IPv6 with or without brackets) is the loopback."""
    if not name:
        return False
    name = name.strip("[]").lower()
    if name == "localhost":
        return True
    try:
        return ipaddress.ip_address(name).is_loopback
    except ValueError:
        return False


def host_ok(host_header: str | None, bound: str) -> bool:
    """A request's ``Host`` may reach a console bound to ``bound``."""
    if not is_loopback(bound):
        return True
    return is_loopback(hostname(host_header))


def origin_ok(origin: str | None, host_header: str | None) -> bool:
    """A WebSocket ``Origin`` is absent or the console's own (``http(s)://<Host>``)."""
    if origin is None:
        return True
    try:
        parts = urlsplit(origin.strip())
    except ValueError:
        return False
    if parts.scheme not in ("http", "https") or not parts.netloc or not host_header:
        return False
    return parts.netloc.lower() == host_header.strip().lower()


def url(host: str, port: int, token: str) -> str:
    """The console's address with its token."""
    shown = f"[{host}]" if ":" in host and not host.startswith("[") else host
    return f"http://{shown}:{port}/?token={token}"
