"""Runs and their control: /api/runs, /api/runs/{id}, start | pause | reset | step, and the live state.

Each run names its owner (who created it); a student's token changes only the student's own runs (403
naming the owner otherwise), a viewer's none (runs/access.py).
"""

from __future__ import annotations

from typing import Annotated, Any

from fastapi import APIRouter, Body, Query, Response, status
from pydantic import TypeAdapter, ValidationError

from horde.runs.access import Access
from horde.runs.errors import SpecError
from horde.runs.evaluations import forget_evaluations
from horde.runs.events import RECENT_EVENTS
from horde.runs.run_view import RunView
from horde.server.convert import run_brief, run_out, state_out
from horde.server.deps import (
    AccessDep,
    CatalogDep,
    ControlledRunDep,
    ManagerDep,
    RunDep,
    StoreDep,
    WriterDep,
    write_router,
)
from horde.server.responses import BAD_BODY, BUSY, CONFLICT, NOT_FOUND, NOT_SAVED
from horde.server.schemas import (
    Hz,
    RunBriefOut,
    RunCreate,
    RunOut,
    RunPatchIn,
    RunTemplateIn,
    StateOut,
    StepIn,
    run_form,
)
from horde.server.spec_builder import template_data

router = APIRouter(prefix="/runs", tags=["runs"])
writes = write_router(router)


def _out(view: RunView, access: Access) -> RunOut:
    return run_out(view, access.owner_name("run", view.id))


@router.get("", summary="List the runs")
def list_runs(manager: ManagerDep, access: AccessDep) -> list[RunBriefOut]:
    views = sorted(manager.list(), key=lambda v: v.created_at)
    return [run_brief(v, access.owner_name("run", v.id)) for v in views]


# The body as the OpenAPI schema shows it (a RunSpec or a template); the route takes it as plain JSON and the run's
# worker validates it, so that a Horde of thousands of demons is validated and compiled off the server's GIL.
RUN_CREATE_BODY = {
    "requestBody": {
        "required": True,
        "content": {"application/json": {"schema": {"oneOf": [{"$ref": "#/components/schemas/RunSpec-Input"},
                                                              {"$ref": "#/components/schemas/RunTemplateIn"}],
                                                    "title": "Body"}}},
    }
}  # fmt: skip
_run_create: TypeAdapter[Any] = TypeAdapter(RunCreate)
_template: TypeAdapter[RunTemplateIn] = TypeAdapter(RunTemplateIn)


@writes.post(
    "",
    summary="Create a run",
    status_code=status.HTTP_201_CREATED,
    responses={**BAD_BODY, **NOT_FOUND, **CONFLICT, **NOT_SAVED},
    openapi_extra=RUN_CREATE_BODY,
)
def create_run(
    body: Annotated[Any, Body()],
    manager: ManagerDep,
    catalog: CatalogDep,
    store: StoreDep,
    me: WriterDep,
    access: AccessDep,
    hz: Annotated[Hz | None, Query(description="steps per second; leave out for full speed")] = None,
    start: Annotated[bool, Query(description="start running at once")] = False,
) -> RunOut:
    """The body is a RunSpec, or a template: {scenario, world, seed, ...overrides} (a body with a `scenario` key, or
    whose `world` is a string naming a stored world). The run is the first trial of its protocol, seeded as `horde
    run` seeds it; it belongs to the requester. The run's worker validates and builds it (a 422 names the field as
    always). 404: unknown scenario or world; 409: too many runs."""
    if not isinstance(body, dict):  # not an object: refused as the union refuses it
        _validated(_run_create, body, ("body",))
    loc: tuple[str | int, ...] = ("body", "RunSpec")
    data = body
    if run_form(body) == "RunTemplate":
        template = _validated(_template, body, ("body", "RunTemplate"))
        data, loc = template_data(template, catalog, store), ("body",)
    view = manager.create_from(data, loc, hz=hz, start=start)
    access.claim(me, "run", view.id)
    return _out(view, access)


def _validated(adapter: TypeAdapter[Any], body: Any, loc: tuple[str | int, ...]) -> Any:
    try:
        return adapter.validate_python(body)
    except ValidationError as exc:
        raise SpecError.from_validation(exc, loc) from None


@router.get("/{run_id}", summary="A run", responses={**NOT_FOUND})
def get_run(run: RunDep, access: AccessDep) -> RunOut:
    return _out(run.view, access)


@writes.delete(
    "/{run_id}", summary="Delete a run", status_code=status.HTTP_204_NO_CONTENT, responses={**NOT_FOUND, **BUSY}
)
def delete_run(run: ControlledRunDep, manager: ManagerDep, access: AccessDep) -> None:
    manager.delete(run.id)
    access.release("run", run.id)


@writes.patch(
    "/{run_id}", summary="Change a run's speed or behaviour policy", responses={**BAD_BODY, **NOT_FOUND, **NOT_SAVED}
)
def patch_run(run: ControlledRunDep, patch: RunPatchIn, access: AccessDep) -> RunOut:
    """`hz: null` runs as fast as possible; a field left out is unchanged."""
    return _out(run.patch(set_hz="hz" in patch.model_fields_set, hz=patch.hz, behaviour=patch.behaviour), access)


@writes.post("/{run_id}/start", summary="Start (or resume) a run", responses={**NOT_FOUND, **CONFLICT, **NOT_SAVED})
def start_run(run: ControlledRunDep, access: AccessDep) -> RunOut:
    """409 unless the run is created or paused."""
    return _out(run.start(), access)


@writes.post("/{run_id}/pause", summary="Pause a running run", responses={**NOT_FOUND, **CONFLICT, **NOT_SAVED})
def pause_run(run: ControlledRunDep, access: AccessDep) -> RunOut:
    """Takes a snapshot. 409 unless the run is running."""
    return _out(run.pause(), access)


@writes.post("/{run_id}/reset", summary="Reset a run to its first step", responses={**NOT_FOUND, **NOT_SAVED})
def reset_run(run: ControlledRunDep, access: AccessDep, store: StoreDep) -> RunOut:
    """Fresh weights and generator, the current demons; the status becomes created. The run's kept evaluations
    are dropped (they described the old weights)."""
    view = run.reset()
    forget_evaluations(store, run.id)
    return _out(view, access)


@writes.post(
    "/{run_id}/step",
    summary="Take steps on a run that is not running",
    responses={**BAD_BODY, **NOT_FOUND, **CONFLICT, **NOT_SAVED},
)
def step_run(run: ControlledRunDep, step: Annotated[StepIn | None, Body()] = None) -> StateOut:
    """Default 1 step. 409 when the run is running, finished or failed."""
    view = run.step((step or StepIn()).steps)
    return state_out(view, run.events.recent(RECENT_EVENTS))


# The latest encoded state of each run, keyed by (view, events) sequence numbers: many clients polling one
# run (a classroom, at 10 Hz each) then cost one encoding per published view instead of one per request.
_encoded_states: dict[str, tuple[tuple[int, int], bytes]] = {}
MAX_ENCODED_STATES = 256


@router.get("/{run_id}/state", summary="The live state of a run", response_model=StateOut, responses={**NOT_FOUND})
def get_state(run: RunDep) -> Response:
    view = run.view
    key = (view.seq, run.events.last_seq)
    cached = _encoded_states.get(run.id)
    if cached is None or cached[0] != key:
        if len(_encoded_states) >= MAX_ENCODED_STATES:
            _encoded_states.clear()
        cached = key, state_out(view, run.events.recent(RECENT_EVENTS)).model_dump_json().encode()
        _encoded_states[run.id] = cached
    return Response(cached[1], media_type="application/json")
