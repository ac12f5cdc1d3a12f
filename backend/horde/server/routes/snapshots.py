"""Snapshots: GET /api/runs/{id}/snapshot exports a run, POST /api/runs/import makes a run of one."""

from __future__ import annotations

from fastapi import APIRouter, status

from horde.runs.snapshot import Snapshot
from horde.server.convert import run_out
from horde.server.deps import ManagerDep, RunDep, WriteAccess
from horde.server.responses import BAD_BODY, CONFLICT, NOT_FOUND, NOT_SAVED, UNAUTHORIZED
from horde.server.schemas import RunOut

router = APIRouter(prefix="/runs", tags=["snapshots"])


@router.get(
    "/{run_id}/snapshot",
    summary="Export a run: weights, traces, generator state, counters, world state",
    responses={**NOT_FOUND},
)
def export_snapshot(run: RunDep) -> Snapshot:
    return run.snapshot()


@router.post(
    "/import",
    summary="Import a snapshot as a new run",
    status_code=status.HTTP_201_CREATED,
    dependencies=[WriteAccess],
    responses={**BAD_BODY, **UNAUTHORIZED, **CONFLICT, **NOT_SAVED},
    description=(
        "The new run continues exactly where the snapshot was taken (paused, or finished). 422 when the "
        "arrays do not fit the spec; 409 when the server holds as many runs as it allows."
    ),
)
def import_snapshot(snapshot: Snapshot, manager: ManagerDep) -> RunOut:
    return run_out(manager.import_snapshot(snapshot))
