"""GET /api/health: is the server up, and how many runs does it hold."""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version

from fastapi import APIRouter

from horde.server.deps import ManagerDep
from horde.server.schemas import HealthOut

router = APIRouter(prefix="/health", tags=["health"])


def _version() -> str:
    try:
        return version("horde-lab")
    except PackageNotFoundError:
        return "unknown"


@router.get("", summary="Server health")
def health(manager: ManagerDep) -> HealthOut:
    return HealthOut(version=_version(), runs=len(manager.list()))
