"""Request dependencies as Annotated aliases: settings, the run manager, the store, a run, who is asking
(`PrincipalDep`, `WriterDep`: runs/access.py's roles), a run they may change, the protocol and study jobs,
the stream hub, the stream runs and the live view.

These functions are the only readers of `app.state` (which `create_app` and its lifespan fill); routes
take what they need as parameters. They take an `HTTPConnection`, so HTTP routes and WebSocket routes
use the same ones.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Annotated, Any

from fastapi import APIRouter, Depends, Path, Security, WebSocket
from fastapi.requests import HTTPConnection
from fastapi.security import HTTPAuthorizationCredentials, HTTPBearer

from horde.runs.access import Access, Principal
from horde.runs.live_run import LiveRun
from horde.runs.manager import RunManager
from horde.runs.protocols import ProtocolJobs
from horde.runs.store import Store
from horde.runs.stream_run import StreamRuns
from horde.server.catalog import ScenarioCatalog
from horde.server.responses import FORBIDDEN, UNAUTHORIZED
from horde.server.settings import Settings
from horde.server.stream import StreamHub
from horde.studies.jobs import StudyJobs
from horde.view.live import LiveView

_bearer = HTTPBearer(
    auto_error=False,
    description="The server's HORDE_TOKEN (the teacher's) or a token it issued (a student's or a viewer's), required "
    "on mutating requests when HORDE_TOKEN is set",
)


def _from_state(attribute: str) -> Callable[[HTTPConnection], Any]:
    """A dependency that reads what the app factory or its lifespan put in `app.state` under `attribute`
    (its type is the Annotated alias's)."""

    def read(connection: HTTPConnection) -> Any:
        return getattr(connection.app.state, attribute)

    read.__name__ = f"get_{attribute}"
    return read


SettingsDep = Annotated[Settings, Depends(_from_state("settings"))]
ManagerDep = Annotated[RunManager, Depends(_from_state("manager"))]
StoreDep = Annotated[Store, Depends(_from_state("store"))]
CatalogDep = Annotated[ScenarioCatalog, Depends(_from_state("catalog"))]
ProtocolsDep = Annotated[ProtocolJobs, Depends(_from_state("protocols"))]
StudiesDep = Annotated[StudyJobs, Depends(_from_state("studies"))]
HubDep = Annotated[StreamHub, Depends(_from_state("hub"))]
StreamsDep = Annotated[StreamRuns, Depends(_from_state("streams"))]  # stream runs (routes/records.py)
AccessDep = Annotated[Access, Depends(_from_state("access"))]  # tokens, owners and the rule (runs/access.py)
LiveViewDep = Annotated[LiveView | None, Depends(_from_state("live_view"))]  # None: the server runs without it
RunId = Annotated[str, Path(min_length=1, max_length=64, description="the run's id")]
DemonName = Annotated[str, Path(min_length=1, max_length=64, description="the demon's name")]


def get_run(run_id: RunId, manager: ManagerDep) -> LiveRun:
    """The run of the path's `run_id` (404 when unknown)."""
    return manager.get(run_id)


RunDep = Annotated[LiveRun, Depends(get_run)]


def _secret(credentials: HTTPAuthorizationCredentials | None) -> str | None:
    return credentials.credentials if credentials is not None else None


Credentials = Annotated[HTTPAuthorizationCredentials | None, Security(_bearer)]


def current_principal(access: AccessDep, credentials: Credentials) -> Principal | None:
    """Who the request acts as (None: no token, on a server with roles); 401 for a wrong or revoked token."""
    return access.identify(_secret(credentials))


def require_writer(access: AccessDep, credentials: Credentials) -> Principal:
    """The teacher or a student (401 without a token or with a wrong or revoked one, 403 for a viewer's)."""
    return access.writer(_secret(credentials))


PrincipalDep = Annotated[Principal | None, Depends(current_principal)]
WriterDep = Annotated[Principal, Depends(require_writer)]
WriteAccess = Depends(require_writer)


def controlled_run(run: RunDep, me: WriterDep, access: AccessDep) -> LiveRun:
    """The path's run, which the requester may change (403 naming its owner when a student's is another's)."""
    access.check(me, "run", run.id)
    return run


ControlledRunDep = Annotated[LiveRun, Depends(controlled_run)]


def socket_principal(websocket: WebSocket, access: Access) -> Principal | None:
    """Who a WebSocket acts as: its `Authorization: Bearer` header, else its `?token=` (a browser's WebSocket
    cannot set headers). Raises UnauthorizedError for a wrong or revoked token."""
    header = websocket.headers.get("authorization", "")
    secret = header.removeprefix("Bearer ") if header.startswith("Bearer ") else None
    return access.identify(secret or websocket.query_params.get("token"))


def write_router(router: APIRouter) -> APIRouter:
    """The router for the routes beside `router`'s (same prefix and tags) that change something: every one
    needs a teacher's or a student's token (`WriteAccess`) and documents its 401 and 403, written here once
    instead of on each route."""
    return APIRouter(
        prefix=router.prefix, tags=router.tags, dependencies=[WriteAccess], responses={**UNAUTHORIZED, **FORBIDDEN}
    )
