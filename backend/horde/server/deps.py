"""Request dependencies as Annotated aliases: settings, the run manager, the store, a run, write access,
the protocol and study jobs, the stream hub, the stream runs and the live view.

These functions are the only readers of `app.state` (which `create_app` and its lifespan fill); routes
take what they need as parameters. They take an `HTTPConnection`, so HTTP routes and WebSocket routes
use the same ones.
"""

from __future__ import annotations

import hmac
from collections.abc import Callable
from typing import Annotated, Any

from fastapi import APIRouter, Depends, HTTPException, Path, Security, status
from fastapi.requests import HTTPConnection
from fastapi.security import HTTPAuthorizationCredentials, HTTPBearer

from horde.runs.live_run import LiveRun
from horde.runs.manager import RunManager
from horde.runs.protocols import ProtocolJobs
from horde.runs.store import Store
from horde.runs.stream_run import StreamRuns
from horde.server.catalog import ScenarioCatalog
from horde.server.responses import UNAUTHORIZED
from horde.server.settings import Settings
from horde.server.stream import StreamHub
from horde.studies.jobs import StudyJobs
from horde.view.live import LiveView

_bearer = HTTPBearer(auto_error=False, description="The server's HORDE_TOKEN, required on mutating requests when set")


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
LiveViewDep = Annotated[LiveView | None, Depends(_from_state("live_view"))]  # None: the server runs without it
RunId = Annotated[str, Path(min_length=1, max_length=64, description="the run's id")]
DemonName = Annotated[str, Path(min_length=1, max_length=64, description="the demon's name")]


def get_run(run_id: RunId, manager: ManagerDep) -> LiveRun:
    """The run of the path's `run_id` (404 when unknown)."""
    return manager.get(run_id)


RunDep = Annotated[LiveRun, Depends(get_run)]


def require_token(
    settings: SettingsDep,
    credentials: Annotated[HTTPAuthorizationCredentials | None, Security(_bearer)],
) -> None:
    """401 unless HORDE_TOKEN is unset or the request carries `Authorization: Bearer <token>`."""
    if settings.token is None:
        return
    expected = settings.token.get_secret_value().encode()
    given = credentials.credentials.encode() if credentials is not None else b""
    if not hmac.compare_digest(given, expected):
        raise HTTPException(
            status_code=status.HTTP_401_UNAUTHORIZED,
            detail="this server requires 'Authorization: Bearer <HORDE_TOKEN>' on requests that change anything",
            headers={"WWW-Authenticate": "Bearer"},
        )


WriteAccess = Depends(require_token)


def write_router(router: APIRouter) -> APIRouter:
    """The router for the routes beside `router`'s (same prefix and tags) that change something: every one
    needs the token (`WriteAccess`) and documents its 401, written here once instead of on each route."""
    return APIRouter(prefix=router.prefix, tags=router.tags, dependencies=[WriteAccess], responses=UNAUTHORIZED)
