"""Parameter studies: POST /api/studies, GET /api/studies[/{id}], cancel, resume, export, progress stream.

A study runs in the background on the server's executor (Ray on this machine by default, the cluster at
HORDE_RAY_ADDRESS when set), as `horde study` runs it; its finished tasks go to the store as they finish.
A study belongs to whoever started it: a student cancels, deletes or resumes only their own.
"""

from __future__ import annotations

import asyncio
import json
from typing import Annotated

from fastapi import APIRouter, Body, Path, Query, WebSocketDisconnect, status
from fastapi.responses import PlainTextResponse, Response

from horde.runs.access import Access
from horde.runs.errors import NotFoundError, SpecError
from horde.runs.store import StudyRecord
from horde.server.convert import timestamp
from horde.server.deps import AccessDep, CatalogDep, StudiesDep, WriterDep, write_router
from horde.server.responses import BAD_BODY, BUSY, CONFLICT, NOT_FOUND
from horde.server.routes.exports import FILE_RESPONSES
from horde.server.sockets import AcceptedSocket
from horde.server.stream_protocol import StreamClose, close_reason
from horde.server.study_schemas import StudyConfigOut, StudyOut, StudyResultsOut
from horde.studies.export import curves_csv, results_csv, results_json
from horde.studies.jobs import StudyJobs
from horde.studies.spec import StudySpec

router = APIRouter(prefix="/studies", tags=["studies"])
writes = write_router(router)

StudyId = Annotated[str, Path(min_length=1, max_length=64, description="the study's id")]
STREAM_INTERVAL = 0.5  # seconds between progress messages


def _out(jobs: StudyJobs, record: StudyRecord, access: Access) -> StudyOut:
    study = StudySpec.model_validate_json(record.spec)
    progress = jobs.progress(record.id)
    # The store's count once the study has stopped: its driver writes each task, then its status, before the
    # last Progress message reaches this process (a `finished` study must not read 7 of 8).
    done = progress.done if progress is not None and record.status == "running" else jobs.tasks_done(record.id)
    base = study.base
    return StudyOut(
        id=record.id,
        owner=access.owner_name("study", record.id),
        name=record.name,
        scenario=base.name if base else study.scenario,
        status=record.status,
        message=record.message,
        axes=study.axes,
        runs=study.runs,
        episodes=study.measure.episodes or (base.protocol.episodes if base else 0),
        configurations=record.tasks // study.runs,
        tasks=record.tasks,
        tasks_done=done,
        seconds_left=progress.seconds_left() if progress is not None else None,
        created_at=timestamp(record.created_at),
        updated_at=timestamp(record.updated_at),
    )


@router.get("", summary="Every study (running, finished, interrupted)")
def list_studies(jobs: StudiesDep, access: AccessDep) -> list[StudyOut]:
    return [_out(jobs, r, access) for r in jobs.records()]


@writes.post(
    "",
    summary="Start a parameter study in the background",
    status_code=status.HTTP_202_ACCEPTED,
    responses={**BAD_BODY, **NOT_FOUND, **BUSY},
)
def start_study(
    body: Annotated[StudySpec, Body()], jobs: StudiesDep, catalog: CatalogDep, me: WriterDep, access: AccessDep
) -> StudyOut:
    """The body is a study, as in a study file: a `scenario` name (or a `base` run spec), `axes` (a field path and its
    values each), `sample`, `runs` per configuration and `measure`. Every axis is checked before any task starts: an
    unknown path, a value the field refuses, or a grid past the bounds is a 422 located at the axis. One study runs
    at a time (429 while one runs)."""
    base = body.base if body.base is not None else catalog.get(body.scenario or "")
    try:
        record = jobs.start(body, base)
    except SpecError as exc:
        raise SpecError([type(p)(("body", *p.loc), p.msg, p.type) for p in exc.problems]) from None
    access.claim(me, "study", record.id)
    return _out(jobs, record, access)


@router.get("/{study_id}", summary="A study: progress, then results per configuration", responses=NOT_FOUND)
def get_study(study_id: StudyId, jobs: StudiesDep, access: AccessDep) -> StudyResultsOut:
    record = jobs.get(study_id)
    out = _out(jobs, record, access)
    results = [StudyConfigOut.model_validate(r) for r in results_json(jobs.summaries(study_id))]
    return StudyResultsOut(**dict(out), results=results, warnings=jobs.warnings(study_id))


@writes.delete(
    "/{study_id}",
    summary="Cancel a running study (finished tasks are kept), or delete a study that is not running",
    responses=NOT_FOUND,
)
def cancel_study(study_id: StudyId, jobs: StudiesDep, me: WriterDep, access: AccessDep) -> StudyOut:
    jobs.get(study_id)
    access.check(me, "study", study_id)
    out = _out(jobs, jobs.cancel(study_id), access)
    try:
        jobs.get(study_id)
    except NotFoundError:  # it was not running: deleted
        access.release("study", study_id)
    return out


@writes.post(
    "/{study_id}/resume",
    summary="Run the unfinished tasks of a cancelled, failed or interrupted study",
    status_code=status.HTTP_202_ACCEPTED,
    responses={**NOT_FOUND, **CONFLICT, **BUSY},
)
def resume_study(study_id: StudyId, jobs: StudiesDep, me: WriterDep, access: AccessDep) -> StudyOut:
    jobs.get(study_id)
    access.check(me, "study", study_id)
    return _out(jobs, jobs.resume(study_id), access)


@router.get(
    "/{study_id}/export",
    summary="A study's results as CSV (a row per configuration and demon), its learning curves as CSV (a row per "
    "configuration, demon and checkpoint) or JSON (as horde study --json)",
    responses={**NOT_FOUND, **FILE_RESPONSES},
)
def export_study(
    study_id: StudyId,
    jobs: StudiesDep,
    format: Annotated[
        str, Query(pattern="^(csv|curves|json)$", description="csv: results; curves: the learning curves (CSV)")
    ] = "csv",
) -> Response:
    record = jobs.get(study_id)
    summaries = jobs.summaries(study_id)
    name = record.name or study_id
    if format == "json":
        text, media, filename = json.dumps(results_json(summaries), indent=2) + "\n", "application/json", f"{name}.json"
    elif format == "curves":
        text, media, filename = curves_csv(summaries), "text/csv", f"{name}-curves.csv"
    else:
        text, media, filename = results_csv(summaries), "text/csv", f"{name}.csv"
    headers = {"Content-Disposition": f'attachment; filename="study-{filename}"'}
    return PlainTextResponse(text, media_type=media, headers=headers)


@router.websocket("/{study_id}/stream")
async def stream_study(websocket: AcceptedSocket, study_id: str, jobs: StudiesDep, access: AccessDep) -> None:
    """Messages have the shape of GET /api/studies (a StudyOut), twice a second while the study runs; the
    last one is sent when it stops. Close codes: 4404 unknown study, 1000 the study stopped, 1008 a page of
    another site (its `Origin`)."""
    try:
        while True:
            try:
                out = _out(jobs, jobs.get(study_id), access)
            except NotFoundError:
                await websocket.close(code=StreamClose.NOT_FOUND, reason=close_reason(f"no study {study_id!r}"))
                return
            await websocket.send_json(out.model_dump(mode="json"))
            if out.status not in ("running", "created"):
                await websocket.close(code=StreamClose.NORMAL)
                return
            await asyncio.sleep(STREAM_INTERVAL)
    except WebSocketDisconnect:
        return
