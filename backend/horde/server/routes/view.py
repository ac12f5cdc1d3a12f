"""The viser live view: GET /api/view (whether and where it listens), POST /api/view (which run it shows).

The view runs in the server's process when `horde serve` starts it (`--viser-port`). Without it GET
says `enabled: false` (and the dashboard shows a note instead of the embedded view) and POST is a 409.
"""

from __future__ import annotations

from fastapi import APIRouter, Request

from horde.runs.errors import ConflictError, NotFoundError
from horde.server.deps import WriteAccess
from horde.server.responses import BAD_BODY, CONFLICT, NOT_FOUND, UNAUTHORIZED
from horde.server.schemas import ViewIn, ViewOut
from horde.view.live import LiveView

router = APIRouter(prefix="/view", tags=["view"])


def _live_view(request: Request) -> LiveView | None:
    view: LiveView | None = getattr(request.app.state, "live_view", None)
    return view


@router.get("", summary="Whether and where the live view listens")
def get_view(request: Request) -> ViewOut:
    view = _live_view(request)
    if view is None:
        return ViewOut(enabled=False, url=None, run=None)
    return ViewOut(enabled=True, url=view.url, run=view.shown_run)


@router.post(
    "",
    summary="Show a run in the live view (every connected browser)",
    dependencies=[WriteAccess],
    responses={**NOT_FOUND, **CONFLICT, **UNAUTHORIZED, **BAD_BODY},
)
def show_run(request: Request, body: ViewIn) -> ViewOut:
    view = _live_view(request)
    if view is None:
        raise ConflictError("the live view is off: `horde serve` starts it (unless --no-view)")
    try:
        view.show(body.run, body.demons)
    except KeyError:
        raise NotFoundError(f"no run {body.run!r}") from None
    return ViewOut(enabled=True, url=view.url, run=body.run)
