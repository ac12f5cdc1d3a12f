"""WS /api/runs/{id}/stream: the run's state as JSON messages (StateOut), about 30 a second at most."""

from __future__ import annotations

from fastapi import APIRouter

from horde.server.deps import HubDep
from horde.server.sockets import AcceptedSocket

router = APIRouter(prefix="/runs", tags=["stream"])


@router.websocket("/{run_id}/stream")
async def stream_run(websocket: AcceptedSocket, run_id: str, hub: HubDep) -> None:
    """Messages have the shape of GET /api/runs/{id}/state, with the events since the previous message.

    Close codes: 4404 unknown run, 4410 run deleted, 1013 client too slow, 1001 server stopping, 1008 a page
    of another site (its `Origin`; the upgrade is accepted, then closed, so that the client sees the code).
    """
    await hub.serve(websocket, run_id)
