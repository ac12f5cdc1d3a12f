"""Which `Host` a request may name: the guard against DNS rebinding, on every route.

A page of another site can make its own name resolve to 127.0.0.1 (DNS rebinding). The browser then
sends that page's requests to this server as same-origin ones, with the page's name in `Host`, and lets
the page read the answers. So every request (REST, the dashboard's files, WebSocket upgrades) must name
this server in `Host`:

- a loopback name: `localhost`, `*.localhost`, 127.0.0.0/8, `[::1]`;
- the address the server binds (`HORDE_HOST`);
- any IP address, when the server binds every interface (0.0.0.0, ::): an address is never a rebound name;
- a name listed in `HORDE_ALLOWED_HOSTS` (`["lab.school.example"]`; `["*"]` accepts any).

Only the name is compared, not the port: a rebinding page controls the name, while the port is the one
the server listens on whatever the name. A request without `Host` (HTTP/1.0) is no browser's and passes.
`HostGuard` answers a refused HTTP request with 400 and a JSON `detail` naming the host and the setting;
a refused WebSocket upgrade is accepted and closed with 1008 (so the client sees why, see sockets.py).
`origins.py` applies the same rule to the `Host` of WebSocket upgrades on the live view's port.
"""

from __future__ import annotations

import ipaddress
import json
from collections.abc import Iterable
from dataclasses import dataclass
from urllib.parse import urlsplit

from horde.server.guard import ASGIApp, Receive, Scope, Send
from horde.server.stream_protocol import StreamClose

LOOPBACK_NAMES = ("localhost",)
EVERY_INTERFACE = ("0.0.0.0", "::")
SETTING = "HORDE_ALLOWED_HOSTS"


def _ip(name: str) -> ipaddress.IPv4Address | ipaddress.IPv6Address | None:
    try:
        return ipaddress.ip_address(name)
    except ValueError:
        return None


def is_loopback_name(hostname: str) -> bool:
    """Whether `hostname` (no port, no brackets) only ever means this machine."""
    hostname = hostname.lower().rstrip(".")
    if hostname in LOOPBACK_NAMES or hostname.endswith(".localhost"):
        return True
    address = _ip(hostname)
    return address is not None and address.is_loopback


def host_name(host: str) -> str | None:
    """The name of a `Host` header ("[::1]:8000" -> "::1"), lower case; None when it is malformed."""
    host = host.strip()
    if not host or any(c in host for c in "@/?#\\ \t"):  # "evil.example@127.0.0.1" names no host of ours
        return None
    try:
        parts = urlsplit(f"//{host}")
        parts.port  # noqa: B018 (raises ValueError for a port that is not a number)
    except ValueError:
        return None
    return (parts.hostname or "").rstrip(".") or None


@dataclass(frozen=True)
class HostRule:
    """The `Host` names this server answers to (see the module docstring).

    Args:
        bound: the address the server binds (`HORDE_HOST`).
        allowed: further names (`HORDE_ALLOWED_HOSTS`); "*" allows any.
    """

    bound: str
    allowed: tuple[str, ...] = ()

    @classmethod
    def of(cls, bound: str, allowed: Iterable[str]) -> HostRule:
        return cls(bound.strip().strip("[]").lower(), tuple(a.strip().lower().rstrip(".") for a in allowed))

    @property
    def loopback_only(self) -> bool:
        """Whether the server listens on this machine only."""
        return is_loopback_name(self.bound)

    def allows(self, host: str | None) -> bool:
        """Whether a request naming `host` (a Host header, None: not sent) is for this server."""
        if host is None:
            return True
        name = host_name(host)
        if name is None:
            return False
        if is_loopback_name(name) or name == self.bound or "*" in self.allowed or name in self.allowed:
            return True
        return self.bound in EVERY_INTERFACE and _ip(name) is not None

    def refusal(self, host: str) -> str:
        """Why a request naming `host` is refused, and what to set."""
        shown = host if len(host) <= 100 else host[:99] + "…"
        return (
            f"this server does not answer to the host {shown!r} (a page that rebinds its name to this machine?): "
            f"add the name to {SETTING} to allow it"
        )


class HostGuard:
    """ASGI middleware: every HTTP request and WebSocket upgrade must name an allowed host (HostRule)."""

    def __init__(self, app: ASGIApp, rule: HostRule) -> None:
        self.app = app
        self.rule = rule

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        host = _header(scope, b"host")
        if scope["type"] not in ("http", "websocket") or self.rule.allows(host):
            await self.app(scope, receive, send)
            return
        assert host is not None  # allows(None) is true
        if scope["type"] == "http":
            body = json.dumps({"detail": self.rule.refusal(host)}).encode()
            headers = [(b"content-type", b"application/json"), (b"content-length", str(len(body)).encode())]
            await send({"type": "http.response.start", "status": 400, "headers": headers})
            await send({"type": "http.response.body", "body": body})
            return
        if (await receive())["type"] == "websocket.connect":
            await send({"type": "websocket.accept"})
            await send(
                {
                    "type": "websocket.close",
                    "code": StreamClose.ORIGIN_REFUSED,
                    "reason": f"host not allowed: see {SETTING}",
                }
            )


def _header(scope: Scope, name: bytes) -> str | None:
    for key, value in scope.get("headers") or ():
        if key == name:
            return bytes(value).decode("latin-1")
    return None
