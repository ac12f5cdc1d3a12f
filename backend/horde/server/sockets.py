"""The one entry of every WebSocket route: accept the upgrade, then refuse with a documented close code.

Why accept first: a WebSocket closed before its handshake completes reaches the client as an HTTP 403,
whatever code the server meant, so a client could not tell a wrong token (4401) from an unknown run
(4404) or a page of another site (1008). Every WebSocket route takes `AcceptedSocket`: the upgrade is
accepted, and one from a page of another site (`origins.origin_allowed`) is closed at once with 1008.
A token presented (`Authorization: Bearer`, or `?token=` since a browser's WebSocket cannot set headers) that is
not the server's or was revoked is refused with 4401; who the socket acts as is left in `websocket.state.principal`
(None: no token, on a server with roles) for the routes that change something.
A route refuses further with `raise WebSocketException(code, close_reason(...))`; starlette then
closes the accepted socket with that code and reason. Nothing is sent before the close, so accepting
a refused page tells it nothing but the code.
"""

from __future__ import annotations

from typing import Annotated

from fastapi import Depends, WebSocket, WebSocketException

from horde.runs.access import UnauthorizedError
from horde.server.deps import AccessDep, SettingsDep, socket_principal
from horde.server.origins import origin_allowed
from horde.server.stream_protocol import StreamClose, close_reason


async def accepted_socket(websocket: WebSocket, settings: SettingsDep, access: AccessDep) -> WebSocket:
    """The route's WebSocket, accepted; closed with 1008 when the page's origin is another site's, with 4401 when
    its token is wrong or revoked."""
    await websocket.accept()
    headers = websocket.headers
    if not origin_allowed(headers.get("origin"), headers.get("host"), settings.host_rule(), settings.origins):
        raise WebSocketException(StreamClose.ORIGIN_REFUSED, "a page of another site may not open this stream")
    try:
        websocket.state.principal = socket_principal(websocket, access)
    except UnauthorizedError as exc:
        raise WebSocketException(StreamClose.UNAUTHORIZED, close_reason(str(exc))) from None
    return websocket


AcceptedSocket = Annotated[WebSocket, Depends(accepted_socket)]
