"""GET /api/health: is the server up, and how many runs does it hold."""

from __future__ import annotations

import functools
from importlib.metadata import PackageNotFoundError, version

from fastapi import APIRouter

from horde.server.deps import ManagerDep
from horde.server.schemas import HealthOut

router = APIRouter(prefix="/health", tags=["health"])


@functools.cache
def _version() -> str:
    try:
        return version("horde-lab")
    except PackageNotFoundError:
        return "unknown"


@router.get("", summary="Server health")
async def health(manager: ManagerDep) -> HealthOut:
    """Answered on the event loop itself (no worker thread to wait for): a measure of its responsiveness."""
    return HealthOut(version=_version(), runs=len(manager.list()))
