"""The viser live view: GET /api/view (whether and where it listens), POST /api/view (which run one dashboard
tab's view shows).

The view runs in the server's process when `horde serve` starts it (`--viser-port`). Without it GET says
`enabled: false` (and the dashboard shows a note instead of the embedded view) and POST is a 409.

Each browser has its own view (`horde.view.live`). A dashboard tab names itself with a random key, embeds
GET /api/view?viewer=<key>'s `url`, and POSTs its selected run with that key: only the browsers of that key
switch. Since it changes no run and nothing anyone else sees, POST /api/view needs no token (a viewer
chooses what it watches); a token sent with it (`Authorization: Bearer`) is what that tab's view acts with,
so the embedded view shows the commands of the runs that token may change (a wrong or revoked one is 401).
"""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Query

from horde.runs.errors import ConflictError, NotFoundError
from horde.server.deps import Credentials, LiveViewDep, PrincipalDep
from horde.server.responses import BAD_BODY, CONFLICT, NOT_FOUND, UNAUTHORIZED
from horde.server.schemas import ViewerKey, ViewIn, ViewOut

router = APIRouter(prefix="/view", tags=["view"])


@router.get("", summary="Whether and where the live view listens (for one dashboard tab, with `viewer`)")
def get_view(view: LiveViewDep, viewer: Annotated[ViewerKey | None, Query()] = None) -> ViewOut:
    if view is None:
        return ViewOut(enabled=False, url=None, run=None)
    load = {"browsers": len(view.viewers()), "frame_rate": round(view.frame_rate(), 2)}
    if viewer is None:
        return ViewOut(enabled=True, url=view.url, run=None, **load)
    return ViewOut(enabled=True, url=view.url_for(viewer), run=view.shown_run(viewer), **load)


@router.post(
    "",
    summary="Show a run in one dashboard tab's live view",
    responses={**NOT_FOUND, **CONFLICT, **BAD_BODY, **UNAUTHORIZED},
)
def show_run(view: LiveViewDep, body: ViewIn, me: PrincipalDep, credentials: Credentials) -> ViewOut:
    if view is None:
        raise ConflictError("the live view is off: `horde serve` starts it (unless --no-view)")
    secret = credentials.credentials if credentials is not None and me is not None else None
    try:
        view.show(body.viewer, body.run, body.demons, body.large, secret)
    except KeyError:
        raise NotFoundError(f"no run {body.run!r}") from None
    return ViewOut(enabled=True, url=view.url_for(body.viewer), run=body.run)
