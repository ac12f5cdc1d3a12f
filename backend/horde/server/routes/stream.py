"""WS /api/runs/{id}/stream: the run's state as JSON messages (StateOut), about 30 a second at most."""

from __future__ import annotations

from fastapi import APIRouter, WebSocket

from horde.server.deps import HubDep, SettingsDep
from horde.server.origins import origin_allowed
from horde.server.stream_protocol import StreamClose

router = APIRouter(prefix="/runs", tags=["stream"])


@router.websocket("/{run_id}/stream")
async def stream_run(websocket: WebSocket, run_id: str, settings: SettingsDep, hub: HubDep) -> None:
    """Messages have the shape of GET /api/runs/{id}/state, with the events since the previous message.

    Close codes: 4404 unknown run, 4410 run deleted, 1013 client too slow, 1001 server stopping. An upgrade
    from a page of another site (its `Origin`) is refused (HTTP 403) before it is accepted.
    """
    headers = websocket.headers
    if not origin_allowed(headers.get("origin"), headers.get("host"), settings.is_loopback(), settings.origins):
        await websocket.close(code=StreamClose.ORIGIN_REFUSED, reason="this page's origin may not open the stream")
        return
    await hub.serve(websocket, run_id)
