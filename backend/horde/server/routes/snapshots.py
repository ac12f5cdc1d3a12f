"""Snapshots: GET /api/runs/{id}/snapshot exports a run, POST /api/runs/import makes a run of one."""

from __future__ import annotations

from fastapi import APIRouter, Response, status

from horde.runs.snapshot import Snapshot
from horde.server.convert import run_out
from horde.server.deps import AccessDep, ManagerDep, RunDep, WriterDep, write_router
from horde.server.responses import BAD_BODY, CONFLICT, NOT_FOUND, NOT_SAVED
from horde.server.schemas import RunOut

router = APIRouter(prefix="/runs", tags=["snapshots"])
writes = write_router(router)


@router.get(
    "/{run_id}/snapshot",
    summary="Export a run: weights, traces, generator state, counters, world state",
    response_model=Snapshot,
    responses={**NOT_FOUND, **CONFLICT},
)
def export_snapshot(run: RunDep) -> Response:
    """The run's worker writes the document (its weights never cross into the server as objects). 409 when the
    run's worker is gone (a run that failed because its worker died)."""
    return Response(run.snapshot(), media_type="application/json")


@writes.post(
    "/import",
    summary="Import a snapshot as a new run",
    status_code=status.HTTP_201_CREATED,
    responses={**BAD_BODY, **CONFLICT, **NOT_SAVED},
)
def import_snapshot(snapshot: Snapshot, manager: ManagerDep, me: WriterDep, access: AccessDep) -> RunOut:
    """The new run continues exactly where the snapshot was taken (paused, or finished); it belongs to the
    requester. 422 when the arrays do not fit the spec; 409 when the server holds as many runs as it allows."""
    view = manager.import_snapshot(snapshot)
    access.claim(me, "run", view.id)
    return run_out(view, access.owner_name("run", view.id))
