"""Request dependencies as Annotated aliases: settings, the run manager, the store, a run, write access,
the protocol and study jobs, the stream hub and the live view.

These functions are the only readers of `app.state` (which `create_app` and its lifespan fill); routes
take what they need as parameters. They take an `HTTPConnection`, so HTTP routes and WebSocket routes
use the same ones.
"""

from __future__ import annotations

import hmac
from typing import Annotated

from fastapi import Depends, HTTPException, Path, Security, status
from fastapi.requests import HTTPConnection
from fastapi.security import HTTPAuthorizationCredentials, HTTPBearer

from horde.runs.live_run import LiveRun
from horde.runs.manager import RunManager
from horde.runs.protocols import ProtocolJobs
from horde.runs.store import Store
from horde.server.catalog import ScenarioCatalog
from horde.server.settings import Settings
from horde.server.stream import StreamHub
from horde.studies.jobs import StudyJobs
from horde.view.live import LiveView

_bearer = HTTPBearer(auto_error=False, description="The server's HORDE_TOKEN, required on mutating requests when set")


def get_settings(connection: HTTPConnection) -> Settings:
    settings: Settings = connection.app.state.settings
    return settings


def get_manager(connection: HTTPConnection) -> RunManager:
    manager: RunManager = connection.app.state.manager
    return manager


def get_store(connection: HTTPConnection) -> Store:
    store: Store = connection.app.state.store
    return store


def get_catalog(connection: HTTPConnection) -> ScenarioCatalog:
    catalog: ScenarioCatalog = connection.app.state.catalog
    return catalog


def get_protocols(connection: HTTPConnection) -> ProtocolJobs:
    jobs: ProtocolJobs = connection.app.state.protocols
    return jobs


def get_studies(connection: HTTPConnection) -> StudyJobs:
    jobs: StudyJobs = connection.app.state.studies
    return jobs


def get_hub(connection: HTTPConnection) -> StreamHub:
    hub: StreamHub = connection.app.state.hub
    return hub


def get_live_view(connection: HTTPConnection) -> LiveView | None:
    """The viser live view, or None when the server runs without it."""
    view: LiveView | None = connection.app.state.live_view
    return view


SettingsDep = Annotated[Settings, Depends(get_settings)]
ManagerDep = Annotated[RunManager, Depends(get_manager)]
StoreDep = Annotated[Store, Depends(get_store)]
CatalogDep = Annotated[ScenarioCatalog, Depends(get_catalog)]
ProtocolsDep = Annotated[ProtocolJobs, Depends(get_protocols)]
StudiesDep = Annotated[StudyJobs, Depends(get_studies)]
HubDep = Annotated[StreamHub, Depends(get_hub)]
LiveViewDep = Annotated[LiveView | None, Depends(get_live_view)]
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
