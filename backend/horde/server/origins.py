"""Which browser pages may open a WebSocket to this server (the stream here, the live view on its port).

Browsers send `Origin` with every WebSocket upgrade and, unlike for `fetch`, no CORS rule stops a page
of another site from opening one. So an upgrade is accepted only from a page of the server itself: its
Origin names the same host and port as the request's `Host`, and, while the server listens on loopback
only, that host is a loopback name (a page that rebinds its own name to 127.0.0.1 carries that name in
`Host`). Origins listed in HORDE_ORIGINS are accepted as well (say a dev server on another port).
A request without `Origin` is no browser page's and is accepted: tokens and loopback guard it.
"""

from __future__ import annotations

import ipaddress
from collections.abc import Iterable
from urllib.parse import urlsplit

LOOPBACK_NAMES = ("localhost",)


def _is_loopback_name(hostname: str) -> bool:
    if hostname in LOOPBACK_NAMES or hostname.endswith(".localhost"):
        return True
    try:
        return ipaddress.ip_address(hostname).is_loopback
    except ValueError:
        return False


def origin_allowed(origin: str | None, host: str | None, loopback_only: bool, extra: Iterable[str] = ()) -> bool:
    """Whether a WebSocket upgrade with these `Origin` and `Host` headers comes from the server's own page.

    Args:
        origin: the Origin header (None: not sent).
        host: the Host header.
        loopback_only: the server listens on loopback only.
        extra: origins accepted besides the server's own ("http://localhost:5173").
    """
    if origin is None:
        return True
    origin = origin.strip().rstrip("/").lower()
    if origin in {o.strip().rstrip("/").lower() for o in extra}:
        return True
    parts = urlsplit(origin)
    if parts.scheme not in ("http", "https") or host is None:
        return False
    if parts.netloc != host.strip().lower():
        return False
    return not loopback_only or _is_loopback_name(parts.hostname or "")
