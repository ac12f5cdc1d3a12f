"""Exports: a run's history (CSV, JSON), a run's spec (TOML), a protocol job's results (CSV, JSON).

Each answers with a file name (Content-Disposition), so a browser saves it. Study results are exported
by GET /api/studies/{id}/export.
"""

from __future__ import annotations

import json
from typing import Annotated, Any

from fastapi import APIRouter, Path, Query
from fastapi.responses import PlainTextResponse, Response

from horde.runs.errors import ConflictError
from horde.runs.exports import HISTORY_FIELDS, PROTOCOL_FIELDS, history_records, protocol_records, spec_toml, to_csv
from horde.server.deps import ProtocolsDep, RunDep
from horde.server.responses import CONFLICT, NOT_FOUND

router = APIRouter(tags=["exports"])

FormatQuery = Annotated[str, Query(pattern="^(csv|json)$", description="csv or json")]
FILE_RESPONSES: dict[int | str, dict[str, Any]] = {
    200: {
        "description": "A file (Content-Disposition: attachment)",
        "content": {"text/csv": {"schema": {"type": "string"}}, "application/json": {"schema": {}}},
    }
}


def _file(records: list[dict[str, Any]], fields: tuple[str, ...], format: str, stem: str) -> Response:
    if format == "json":
        text, media = json.dumps(records, indent=1) + "\n", "application/json"
    else:
        text, media = to_csv(records, fields), "text/csv"
    return PlainTextResponse(
        text, media_type=media, headers={"Content-Disposition": f'attachment; filename="{stem}.{format}"'}
    )


@router.get(
    "/runs/{run_id}/export/history",
    summary="A run's history: step, demon, prediction, cumulant, delta, RUPEE, UDE for every kept row",
    responses={**NOT_FOUND, **FILE_RESPONSES},
)
def export_history(run: RunDep, format: FormatQuery = "csv") -> Response:
    return _file(history_records(run.history), HISTORY_FIELDS, format, f"run-{run.id}-history")


@router.get(
    "/runs/{run_id}/export/spec",
    summary="A run's spec as a TOML scenario file (horde run reads it back)",
    responses={
        **NOT_FOUND,
        200: {"description": "A TOML file", "content": {"application/toml": {"schema": {"type": "string"}}}},
    },
)
def export_spec(run: RunDep) -> Response:
    spec = run.view.spec
    return PlainTextResponse(
        spec_toml(spec),
        media_type="application/toml",
        headers={"Content-Disposition": f'attachment; filename="{spec.name or "run-" + run.id}.toml"'},
    )


@router.get(
    "/protocols/{job_id}/export",
    summary="A protocol job's results: per demon prediction, truth ± stderr, error, thesis, test-run counts",
    responses={**NOT_FOUND, **CONFLICT, **FILE_RESPONSES},
)
def export_protocol(
    job_id: Annotated[str, Path(min_length=1, max_length=64)], jobs: ProtocolsDep, format: FormatQuery = "csv"
) -> Response:
    job = jobs.get(job_id)
    if job.result is None:
        raise ConflictError(f"protocol job {job_id!r} has no results ({job.status})")
    return _file(protocol_records(job.result), PROTOCOL_FIELDS, format, f"protocol-{job.spec.name or job_id}")
