"""Who may talk to the console (pure functions on strings, used by :mod:`dvqp.console.server`).

Every request carries the token (else 401). A console bound to a loopback address answers only
a loopback ``Host`` (against DNS rebinding), and a WebSocket ``Origin``, if sent, must be the
console's own, so another site open in the same browser cannot drive the arm (else 403).
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
    try:
        return is_loopback(urlsplit("//" + (host_header or "")).hostname)
    except ValueError:  # not a host name
        return False


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
