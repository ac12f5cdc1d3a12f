"""Protocol jobs: POST /api/protocols (run a scenario's protocol), GET /api/protocols[/{id}], DELETE.

The protocol is `horde run`'s: trials x episodes from scratch, each demon's prediction at the start
beside its Monte-Carlo truth and the thesis's number, and for control protocols where the test runs
ended. It runs in the background; poll GET /api/protocols/{id} for its progress and results. A job belongs to
whoever started it: a student cancels or forgets only their own.
"""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Body, Path, status

from horde.runs.access import Access
from horde.runs.errors import NotFoundError
from horde.runs.protocols import ProtocolJob
from horde.server.convert import timestamp
from horde.server.deps import AccessDep, CatalogDep, ProtocolsDep, StoreDep, WriterDep, write_router
from horde.server.responses import BAD_BODY, BUSY, NOT_FOUND
from horde.server.schemas import CountsOut, DemonResultOut, ProtocolOut, RunCreate, RunTemplateIn
from horde.server.spec_builder import build_spec

router = APIRouter(prefix="/protocols", tags=["protocols"])
writes = write_router(router)

JobId = Annotated[str, Path(min_length=1, max_length=64, description="the protocol job's id")]


def _out(job: ProtocolJob, access: Access) -> ProtocolOut:
    result = job.result
    protocol = job.spec.protocol
    counts = job.spec.thesis.counts
    return ProtocolOut(
        id=job.id,
        owner=access.owner_name("protocol", job.id),
        name=job.spec.name,
        seed=job.spec.seed,
        status=job.status,
        episodes_done=job.episodes_done,
        episodes_total=job.episodes_total,
        trials=protocol.trials,
        episodes=protocol.episodes,
        max_steps=job.spec.grid.max_steps,
        rollouts=protocol.evaluation.rollouts,
        seconds=result.seconds if result else None,
        steps=result.steps if result else None,
        results=[DemonResultOut.model_validate(d, from_attributes=True) for d in result.demons] if result else None,
        thesis_counts=CountsOut.model_validate(counts, from_attributes=True) if counts else None,
        error=job.error,
        created_at=timestamp(job.created_at),
        finished_at=timestamp(job.finished_at) if job.finished_at is not None else None,
    )


@router.get("", summary="The protocol jobs (running and recent)")
def list_protocols(jobs: ProtocolsDep, access: AccessDep) -> list[ProtocolOut]:
    return [_out(job, access) for job in jobs.list()]


@writes.post(
    "",
    summary="Run a scenario's protocol in the background",
    status_code=status.HTTP_202_ACCEPTED,
    responses={**BAD_BODY, **NOT_FOUND, **BUSY},
)
def start_protocol(
    body: Annotated[RunCreate, Body()],
    jobs: ProtocolsDep,
    catalog: CatalogDep,
    store: StoreDep,
    me: WriterDep,
    access: AccessDep,
) -> ProtocolOut:
    """The body is a RunSpec, or a template {scenario, seed, protocol: {trials, episodes}, ...}. One protocol runs at a
    time (429 while one runs). Poll GET /api/protocols/{id} for progress and results."""
    spec = build_spec(body, catalog, store) if isinstance(body, RunTemplateIn) else body
    job = jobs.start(spec)
    access.claim(me, "protocol", job.id)
    return _out(job, access)


@router.get("/{job_id}", summary="A protocol job: progress, then results", responses=NOT_FOUND)
def get_protocol(job_id: JobId, jobs: ProtocolsDep, access: AccessDep) -> ProtocolOut:
    return _out(jobs.get(job_id), access)


@writes.delete("/{job_id}", summary="Cancel a running protocol job, or forget a finished one", responses=NOT_FOUND)
def cancel_protocol(job_id: JobId, jobs: ProtocolsDep, me: WriterDep, access: AccessDep) -> ProtocolOut:
    jobs.get(job_id)
    access.check(me, "protocol", job_id)
    out = _out(jobs.cancel(job_id), access)
    try:
        jobs.get(job_id)
    except NotFoundError:  # it had finished: forgotten
        access.release("protocol", job_id)
    return out
