"""The textbook lab (horde.lab): GET /api/lab lists its experiments; POST /api/lab/{id}/prepare applies a student's
set-up and answers the run spec (for POST /api/runs) or the study (for POST /api/studies) to launch."""

from __future__ import annotations

from typing import Annotated, Any, Literal

from fastapi import APIRouter, Path
from pydantic import Field

from horde.lab import EXPERIMENTS, SETUP_NAMES, experiment, setup_run, setup_study
from horde.runs.errors import FieldProblem, NotFoundError, SpecError
from horde.server.deps import write_router
from horde.server.responses import BAD_BODY, NOT_FOUND
from horde.server.schemas import Out
from horde.spec import Model

router = APIRouter(prefix="/lab", tags=["lab"])
writes = write_router(router)  # a POST, so it takes the token as every POST does (it writes nothing)
ExperimentId = Annotated[str, Path(min_length=1, max_length=64, description="the experiment's id")]


class LabSettingOut(Out):
    name: str
    value: str = Field(description="as shipped: one number for a run, numbers separated by commas for a figure")


class LabExperimentOut(Out):
    id: str
    title: str
    kind: Literal["run", "study"] = Field(description="run: a scenario launched live; study: a figure")
    source: str = Field(description="the scenario's or the study file's name")
    see: str = Field(description="what the class should see")
    setup: list[LabSettingOut]


class LabSetupIn(Model):
    setup: dict[str, Annotated[str, Field(max_length=200)]] = Field(
        default_factory=dict, max_length=len(SETUP_NAMES), description="alpha, lambda, order, runs: as typed"
    )


class LabPreparedOut(Out):
    kind: Literal["run", "study"]
    spec: dict[str, Any] = Field(description="a RunSpec (POST /api/runs) or a StudySpec (POST /api/studies)")


def _out(entry_id: str) -> LabExperimentOut:
    entry = experiment(entry_id)
    settings = [LabSettingOut(name=s.name, value=s.value) for s in entry.setup]
    if entry.kind == "study":
        settings.append(LabSettingOut(name="runs", value=str(setup_study(entry.id, {})[0].runs)))
    return LabExperimentOut(id=entry.id, title=entry.title, kind=entry.kind, source=entry.source, see=entry.see,
                            setup=settings)  # fmt: skip


@router.get("", summary="The textbook lab's experiments")
def list_lab() -> list[LabExperimentOut]:
    return [_out(entry.id) for entry in EXPERIMENTS]


@writes.post(
    "/{experiment_id}/prepare", summary="An experiment with a set-up applied", responses={**BAD_BODY, **NOT_FOUND}
)
def prepare(experiment_id: ExperimentId, body: LabSetupIn) -> LabPreparedOut:
    """The spec to launch: 422 naming the set-up field (`body.setup.<name>`) whose value the field refuses."""
    try:
        entry = experiment(experiment_id)
    except KeyError:
        raise NotFoundError(f"no lab experiment {experiment_id!r}") from None
    try:
        if entry.kind == "run":
            spec = setup_run(entry.id, body.setup).model_dump(mode="json", by_alias=True)
        else:
            spec = setup_study(entry.id, body.setup)[0].model_dump(mode="json", by_alias=True)
    except SpecError as exc:
        raise SpecError([FieldProblem(("body", *p.loc), p.msg) for p in exc.problems]) from None
    return LabPreparedOut(kind=entry.kind, spec=spec)
