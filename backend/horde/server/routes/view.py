"""The viser live view: GET /api/view (where it listens), POST /api/view (which run it shows).

The view runs in the server's process when `horde serve` starts it (`--viser-port`); without it these
routes answer 404, and the dashboard shows a note instead of the embedded view.
"""

from __future__ import annotations

from fastapi import APIRouter, Request

from horde.errors import NotFoundError
from horde.server.deps import WriteAccess
from horde.server.responses import BAD_BODY, NOT_FOUND, UNAUTHORIZED
from horde.server.schemas import ViewIn, ViewOut
from horde.view.live import LiveView

router = APIRouter(prefix="/view", tags=["view"])


def _live_view(request: Request) -> LiveView:
    view: LiveView | None = getattr(request.app.state, "live_view", None)
    if view is None:
        raise NotFoundError("the live view is off: start the server with `horde serve` (it has --viser-port)")
    return view


@router.get("", summary="Where the live view listens", responses=NOT_FOUND)
def get_view(request: Request) -> ViewOut:
    view = _live_view(request)
    return ViewOut(url=view.url, run=view.shown_run)


@router.post(
    "",
    summary="Show a run in the live view (every connected browser)",
    dependencies=[WriteAccess],
    responses={**NOT_FOUND, **UNAUTHORIZED, **BAD_BODY},
)
def show_run(request: Request, body: ViewIn) -> ViewOut:
    view = _live_view(request)
    try:
        view.show(body.run)
    except KeyError:
        raise NotFoundError(f"no run {body.run!r}") from None
    return ViewOut(url=view.url, run=body.run)
