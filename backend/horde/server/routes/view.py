"""The viser live view: GET /api/view (whether and where it listens), POST /api/view (which run it shows).

The view runs in the server's process when `horde serve` starts it (`--viser-port`). Without it GET
says `enabled: false` (and the dashboard shows a note instead of the embedded view) and POST is a 409.
"""

from __future__ import annotations

from fastapi import APIRouter

from horde.runs.errors import ConflictError, NotFoundError
from horde.server.deps import LiveViewDep, write_router
from horde.server.responses import BAD_BODY, CONFLICT, NOT_FOUND
from horde.server.schemas import ViewIn, ViewOut

router = APIRouter(prefix="/view", tags=["view"])
writes = write_router(router)


@router.get("", summary="Whether and where the live view listens")
def get_view(view: LiveViewDep) -> ViewOut:
    if view is None:
        return ViewOut(enabled=False, url=None, run=None)
    return ViewOut(enabled=True, url=view.url, run=view.shown_run)


@writes.post(
    "", summary="Show a run in the live view (every connected browser)", responses={**NOT_FOUND, **CONFLICT, **BAD_BODY}
)
def show_run(view: LiveViewDep, body: ViewIn) -> ViewOut:
    if view is None:
        raise ConflictError("the live view is off: `horde serve` starts it (unless --no-view)")
    try:
        view.show(body.run, body.demons)
    except KeyError:
        raise NotFoundError(f"no run {body.run!r}") from None
    return ViewOut(enabled=True, url=view.url, run=body.run)
