"""WS /api/runs/{id}/stream: the run's state as JSON messages (StateOut), about 30 a second at most."""

from __future__ import annotations

from fastapi import APIRouter, WebSocket

from horde.server.stream import StreamHub

router = APIRouter(prefix="/runs", tags=["stream"])


@router.websocket("/{run_id}/stream")
async def stream_run(websocket: WebSocket, run_id: str) -> None:
    """Messages have the shape of GET /api/runs/{id}/state, with the events since the previous message.

    Close codes: 4404 unknown run, 4410 run deleted, 1013 client too slow, 1001 server stopping.
    """
    hub: StreamHub = websocket.app.state.hub
    await hub.serve(websocket, run_id)
