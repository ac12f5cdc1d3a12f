"""Which browser pages may open a WebSocket to this server (the stream here, the live view on its port).

Browsers send `Origin` with every WebSocket upgrade and, unlike for `fetch`, no CORS rule stops a page
of another site from opening one. So an upgrade is accepted only from a page of the server itself: its
Origin names the same host and port as the request's `Host`, and that host is one the server answers to
(`hosts.HostRule`: a page that rebinds its own name to 127.0.0.1 carries that name in `Host`). Origins
listed in HORDE_ORIGINS are accepted as well (say a dev server on another port). A request without
`Origin` is no browser page's and is accepted: tokens and loopback guard it.
"""

from __future__ import annotations

from collections.abc import Iterable
from urllib.parse import urlsplit

from horde.server.hosts import HostRule


def origin_allowed(origin: str | None, host: str | None, hosts: HostRule, extra: Iterable[str] = ()) -> bool:
    """Whether a WebSocket upgrade with these `Origin` and `Host` headers comes from the server's own page.

    Args:
        origin: the Origin header (None: not sent).
        host: the Host header.
        hosts: the names the server answers to.
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
    return parts.netloc == host.strip().lower() and hosts.allows(host)
