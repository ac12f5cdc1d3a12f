"""The scenario files, read-only: GET /api/scenarios and GET /api/scenarios/{name}."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Path

from horde.server.deps import CatalogDep
from horde.server.responses import CONFLICT, NOT_FOUND
from horde.server.schemas import ScenarioOut
from horde.spec import RunSpec

router = APIRouter(prefix="/scenarios", tags=["scenarios"])


@router.get("", summary="List the scenarios")
def list_scenarios(catalog: CatalogDep) -> list[ScenarioOut]:
    return [
        ScenarioOut(name=e.name, description=e.description, error=e.error, watch_hz=e.watch.hz, watch_note=e.watch.note)
        for e in catalog.entries()
    ]


@router.get(
    "/{name}",
    summary="A scenario's RunSpec",
    responses={**NOT_FOUND, **CONFLICT},
    description="409 when the file exists but does not load (the message names file, line and field).",
)
def get_scenario(name: Annotated[str, Path(min_length=1, max_length=64)], catalog: CatalogDep) -> RunSpec:
    return catalog.get(name)
