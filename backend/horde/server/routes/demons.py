"""A run's demons: list, join, leave, value maps, history and Monte-Carlo evaluation (kept with the run:
`GET /api/runs/{id}/evaluations`, runs/evaluations.py). Joining, leaving and evaluating are the run owner's
(or the teacher's) to do."""

from __future__ import annotations

import asyncio
import threading
from typing import Annotated

from fastapi import APIRouter, Query, Request, Response, status
from starlette.concurrency import run_in_threadpool

from horde.core.evaluate import StoppedError
from horde.runs.errors import NotFoundError
from horde.runs.evaluations import keep_evaluation, kept_evaluations
from horde.runs.run_view import RunView
from horde.server.convert import demons_out, evaluation_out, history_out, values_out
from horde.server.deps import ControlledRunDep, DemonName, ManagerDep, RunDep, StoreDep, write_router
from horde.server.responses import BAD_BODY, BUSY, CONFLICT, NOT_FOUND, NOT_SAVED
from horde.server.schemas import (
    MAX_EVAL_CAP,
    MAX_RESOLUTION,
    DemonOut,
    EvaluateIn,
    EvaluationOut,
    HistoryOut,
    ValuesOut,
)
from horde.spec import DemonSpec

router = APIRouter(prefix="/runs/{run_id}", tags=["demons"])
HANG_UP_POLL = 0.25  # seconds between checks that an evaluation's client still waits
CLIENT_CLOSED_REQUEST = 499  # the answer to a client that hung up (never read; nginx's name and number)
writes = write_router(router)


def _demon(view: RunView, name: str) -> DemonOut:
    for demon in demons_out(view):
        if demon.name == name:
            return demon
    raise NotFoundError(f"run {view.id!r} has no demon {name!r}")


@router.get("/demons", summary="A run's demons", responses={**NOT_FOUND})
def list_demons(run: RunDep) -> list[DemonOut]:
    return demons_out(run.view)


@writes.post(
    "/demons",
    summary="Add a demon to a run (live runs too)",
    status_code=status.HTTP_201_CREATED,
    responses={**BAD_BODY, **NOT_FOUND, **CONFLICT, **NOT_SAVED},
)
def add_demon(run: ControlledRunDep, demon: DemonSpec) -> DemonOut:
    """The other demons keep their weights; traces restart. 409 when the name is taken or the run is finished or
    failed; 422 when the demon does not fit the run (unknown demon or sensor, a cycle)."""
    return _demon(run.add_demon(demon), demon.name)


@router.get("/demons/{name}", summary="One demon", responses={**NOT_FOUND})
def get_demon(run: RunDep, name: DemonName) -> DemonOut:
    return _demon(run.view, name)


@writes.delete(
    "/demons/{name}",
    summary="Remove a demon from a run",
    status_code=status.HTTP_204_NO_CONTENT,
    responses={**NOT_FOUND, **CONFLICT, **NOT_SAVED},
)
def remove_demon(run: ControlledRunDep, name: DemonName) -> None:
    """409 when other demons or the behaviour depend on it, or the run is finished or failed."""
    run.remove_demon(name)


@router.get("/demons/{name}/values", summary="A demon's prediction over the world", responses={**NOT_FOUND, **CONFLICT})
def get_values(
    run: RunDep,
    name: DemonName,
    resolution: Annotated[int, Query(ge=2, le=MAX_RESOLUTION)] = 32,
) -> ValuesOut:
    """The prediction at the centres of a resolution x resolution grid, with the current weights (read by the run's
    worker). 409 when the run's worker is gone."""
    values = run.value_map(name, resolution)
    return values_out(run.view, name, values)


@router.get(
    "/demons/{name}/history",
    summary="A demon's prediction, cumulant, TD error, RUPEE and UDE over time",
    responses={**NOT_FOUND},
)
def get_history(
    run: RunDep,
    name: DemonName,
    limit: Annotated[int | None, Query(ge=1, le=1_000_000, description="the last rows only")] = None,
) -> HistoryOut:
    history = run.history
    try:
        series = history.series(name, limit)
    except KeyError:
        raise NotFoundError(f"run {run.id!r} has no demon {name!r}") from None
    return history_out(name, series, history.every, history.rows)


@writes.post(
    "/evaluate",
    response_model=EvaluationOut,
    summary="Monte-Carlo truth of a demon's question vs its prediction",
    responses={**BAD_BODY, **NOT_FOUND, **BUSY},
)
async def evaluate(
    run: ControlledRunDep, evaluation: EvaluateIn, manager: ManagerDep, store: StoreDep, request: Request
) -> EvaluationOut | Response:
    """Rolls the demon's target policy out with frozen weights (its own generator: the run is not disturbed), as
    the run's world allows (its `evaluation`): on the grid from `from` (default: the world's start), on a
    Gymnasium world from the agent's current state. 422 when `from` lies outside the world or in an obstacle, is
    given on a world without points, or the demon's question cannot be rolled out there, or when the rollouts do
    not finish within HORDE_EVALUATION_SECONDS (at `episodes`: ask for fewer, or a smaller `cap`); 429 when two
    evaluations are running already. A client that hangs up ends its evaluation (the grid's rollouts stop at
    their next chunk). The answer is kept with the run (the latest of each demon; a reset drops them)."""
    cap = evaluation.cap or min(run.view.spec.protocol.evaluation.cap, MAX_EVAL_CAP)
    start = (evaluation.from_[0], evaluation.from_[1]) if evaluation.from_ is not None else None
    gone = threading.Event()

    def evaluate_now() -> EvaluationOut:
        result = manager.evaluate(run.id, evaluation.demon, start, evaluation.episodes, cap, evaluation.seed,
                                  abandoned=gone.is_set)  # fmt: skip
        out = evaluation_out(result)
        keep_evaluation(store, run.id, out.demon, out.model_dump_json(by_alias=True))
        return out

    watcher = asyncio.create_task(_watch_for_hang_up(request, gone))
    try:
        return await run_in_threadpool(evaluate_now)
    except StoppedError:  # the client hung up: nobody reads this answer
        return Response(status_code=CLIENT_CLOSED_REQUEST)
    finally:
        watcher.cancel()


async def _watch_for_hang_up(request: Request, gone: threading.Event) -> None:
    """Set `gone` once the client's connection closes (checked every HANG_UP_POLL seconds)."""
    while not await request.is_disconnected():
        await asyncio.sleep(HANG_UP_POLL)
    gone.set()


@router.get("/evaluations", summary="The run's kept evaluations, the latest of each demon", responses=NOT_FOUND)
def evaluations(run: RunDep, store: StoreDep) -> list[EvaluationOut]:
    return [EvaluationOut.model_validate_json(data) for data in kept_evaluations(store, run.id)]
