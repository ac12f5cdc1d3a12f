"""Request dependencies as Annotated aliases: settings, the run manager, the store, a run, write access."""

from __future__ import annotations

import hmac
from typing import Annotated

from fastapi import Depends, HTTPException, Path, Request, Security, status
from fastapi.security import HTTPAuthorizationCredentials, HTTPBearer

from horde.runs.live_run import LiveRun
from horde.runs.manager import RunManager
from horde.runs.store import Store
from horde.server.catalog import ScenarioCatalog
from horde.server.settings import Settings

_bearer = HTTPBearer(auto_error=False, description="The server's HORDE_TOKEN, required on mutating requests when set")


def get_settings(request: Request) -> Settings:
    settings: Settings = request.app.state.settings
    return settings


def get_manager(request: Request) -> RunManager:
    manager: RunManager = request.app.state.manager
    return manager


def get_store(request: Request) -> Store:
    store: Store = request.app.state.store
    return store


def get_catalog(request: Request) -> ScenarioCatalog:
    catalog: ScenarioCatalog = request.app.state.catalog
    return catalog


SettingsDep = Annotated[Settings, Depends(get_settings)]
ManagerDep = Annotated[RunManager, Depends(get_manager)]
StoreDep = Annotated[Store, Depends(get_store)]
CatalogDep = Annotated[ScenarioCatalog, Depends(get_catalog)]
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
