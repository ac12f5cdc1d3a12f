"""Stream runs: POST|GET /api/streams, GET|DELETE /api/streams/{id}, POST /api/streams/{id}/records and
WS /api/streams/{id}/records, where a client (a robot, a replayed log) pushes records and reads predictions;
GET /api/streams/{id}/phase-plane and /history for what the live view and the dashboard draw.

A record is {observation: [S readings], action, behaviour_probabilities?: [A]} (horde.worlds.records). The
REST route takes a batch whole or not at all: any refused record is a 422 naming it
(`body.records.<i>.<field>`), and nothing of that batch is learned; the run goes on with later batches.
The WebSocket takes messages `{"records": [...]}` (at most 10,000 records; a larger message, one that is
not JSON, a binary frame, or JSON nested more than 48 levels, is refused whole with an error naming
`message`, and the connection stays open) or one record, learns them in order, and answers each
learned message (several queued messages are learned together) with
`{"type": "learned", "received", "learned", "predictions": [D]}`; a refused record gets
`{"type": "error", "index", "field", "message"}` and the stream goes on with the next good one. Back-pressure:
at most QUEUE messages wait to be learned; beyond that the server stops reading the socket, so a fast
sender waits (TCP flow control) instead of growing the server's memory. A stream run belongs to whoever
started it: a student pushes to, or deletes, only their own (403 naming the owner; 4403 on the WebSocket).
"""

from __future__ import annotations

import asyncio
import contextlib
import json
from collections.abc import Mapping
from typing import Annotated, Any

import numpy as np
from fastapi import APIRouter, Path, Query, Response, WebSocket, WebSocketDisconnect, WebSocketException, status
from pydantic import Field

from horde.runs.access import Access, ForbiddenError
from horde.runs.errors import FieldProblem, NotFoundError, RunError, SpecError
from horde.runs.stream_run import HISTORY, MAX_RECORDS_PER_BATCH, PushResult, StreamRun
from horde.runs.stream_snapshot import StreamSnapshot
from horde.server.deps import AccessDep, StreamsDep, WriterDep, write_router
from horde.server.guard import MAX_JSON_DEPTH, json_problem
from horde.server.responses import BAD_BODY, BUSY, CONFLICT, NOT_FOUND
from horde.server.schemas import DemonMetricsOut, DemonOut, In, Out
from horde.server.sockets import AcceptedSocket
from horde.server.stream_protocol import StreamClose, close_reason
from horde.spec import RunSpec
from horde.view.palette import demon_colour
from horde.worlds.phase_plane import MAX_PHASE_RESOLUTION

router = APIRouter(prefix="/streams", tags=["streams"])
writes = write_router(router)
QUEUE = 8  # WebSocket messages waiting to be learned, at most
NO_TOKEN = "this server requires a token, HORDE_TOKEN or one issued (Bearer or ?token=)"
MAX_HISTORY_SERIES = 16  # sensors or demons one history request may name


StreamId = Annotated[str, Path(min_length=1, max_length=64, description="the stream run's id")]


class RecordIn(In):
    """One time step: what the sensors read, the action then taken, and (optionally) b(. | s)."""

    observation: list[float] = Field(max_length=1024, description="one reading per sensor, in the world's order")
    action: int = Field(description="the action taken after this observation, in [0, actions)")
    behaviour_probabilities: list[float] | None = Field(
        default=None, max_length=64, description="b(a | s) of every action (uniform when left out)"
    )


class RecordsIn(In):
    records: list[RecordIn] = Field(min_length=1, max_length=MAX_RECORDS_PER_BATCH)


class StreamOut(Out):
    id: str
    owner: str = Field(description="who started it: 'teacher', or the name of the student's token")
    name: str = Field(default="", description="the run spec's name")
    sensors: list[str]
    actions: int
    demons: list[str]
    received: int = Field(description="records received, good or refused")
    learned: int = Field(description="good records taken in (the first observed, every later one learned)")
    predictions: dict[str, float] = Field(description="each demon's prediction at the last observation")


def _out(run: StreamRun, result: PushResult, access: Access) -> StreamOut:
    return StreamOut(
        id=run.id,
        owner=access.owner_name("stream", run.id),
        name=run.spec.name or "",
        sensors=run.spec.world.sensor_names(),
        actions=run.spec.world.num_actions(),
        demons=run.names,
        received=result.received,
        learned=result.learned,
        predictions=dict(zip(run.names, result.predictions.tolist(), strict=True)),
    )


@writes.post(
    "",
    summary="Start a stream run (a run spec whose world is of kind 'stream')",
    status_code=status.HTTP_201_CREATED,
    responses={**BAD_BODY, **BUSY},
)
def create_stream(spec: RunSpec, streams: StreamsDep, me: WriterDep, access: AccessDep) -> StreamOut:
    run = streams.create(spec)
    access.claim(me, "stream", run.id)
    return _out(run, run.status(), access)


@router.get("", summary="Every stream run, oldest first, with its counters and predictions")
def list_streams(streams: StreamsDep, access: AccessDep) -> list[StreamOut]:
    return [_out(run, run.status(), access) for run in sorted(streams.list(), key=lambda r: r.created)]


@router.get("/{stream_id}", summary="A stream run's counters and predictions", responses=NOT_FOUND)
def get_stream(stream_id: StreamId, streams: StreamsDep, access: AccessDep) -> StreamOut:
    run = streams.get(stream_id)
    return _out(run, run.status(), access)


@router.get("/{stream_id}/demons", summary="A stream run's demon table", responses={**NOT_FOUND, **CONFLICT})
def get_stream_demons(stream_id: StreamId, streams: StreamsDep) -> list[DemonOut]:
    """Each demon's prediction at the last observation and its error measures (null where it diverged)."""
    run = streams.get(stream_id)
    out, step_size = run.readout()
    prediction = np.where(out.diverged, np.nan, out.prediction)  # [D]
    return [
        DemonOut(name=spec.name, spec=spec, control=run.control[i], prediction=prediction[i],
                 metrics=DemonMetricsOut(rupee=out.rupee[i], ude=out.ude[i], delta=out.delta[i],
                                         cumulant=out.cumulant[i], diverged=bool(out.diverged[i]),
                                         step_size=step_size[i]),
                 colour=demon_colour(i))
        for i, spec in enumerate(run.spec.demons)
    ]  # fmt: skip


@router.get(
    "/{stream_id}/snapshot",
    summary="A stream run's learner, to import elsewhere",
    response_model=StreamSnapshot,
    responses={**NOT_FOUND, **CONFLICT},
)
def get_stream_snapshot(stream_id: StreamId, streams: StreamsDep) -> Response:
    return Response(streams.get(stream_id).snapshot(), media_type="application/json")


@writes.post(
    "/import",
    summary="A new stream run from a snapshot: it learns the next record as the exported run would have",
    status_code=status.HTTP_201_CREATED,
    responses={**BAD_BODY, **BUSY},
)
def import_stream(snapshot: StreamSnapshot, streams: StreamsDep, me: WriterDep, access: AccessDep) -> StreamOut:
    run = streams.import_snapshot(snapshot)
    access.claim(me, "stream", run.id)
    return _out(run, run.status(), access)


@writes.delete(
    "/{stream_id}", summary="Stop and forget a stream run", status_code=status.HTTP_204_NO_CONTENT, responses=NOT_FOUND
)
def delete_stream(stream_id: StreamId, streams: StreamsDep, me: WriterDep, access: AccessDep) -> Response:
    streams.get(stream_id)
    access.check(me, "stream", stream_id)
    streams.delete(stream_id)
    access.release("stream", stream_id)
    return Response(status_code=status.HTTP_204_NO_CONTENT)


@writes.post(
    "/{stream_id}/records",
    summary="Learn a batch of records, in order (all or nothing)",
    responses={**NOT_FOUND, **BAD_BODY, **CONFLICT},
)
def push_records(
    stream_id: StreamId, body: RecordsIn, streams: StreamsDep, me: WriterDep, access: AccessDep
) -> StreamOut:
    run = streams.get(stream_id)
    access.check(me, "stream", stream_id)
    items = [r.model_dump() for r in body.records]
    result = run.push(items, whole=True)
    if result.refused:
        raise SpecError([FieldProblem(("body", "records", r.index, *r.field.split(".")), r.message)
                         for r in result.refused[:20]])  # fmt: skip
    return _out(run, result, access)


class AxisOut(Out):
    sensor: str
    low: float
    high: float


class PhasePlaneOut(Out):
    demon: str
    x: AxisOut
    y: AxisOut
    values: list[list[float | None]] = Field(description="[y cell][x cell] the demon's prediction (null: diverged)")
    trail: list[list[float]] = Field(description="the recent (x, y) readings, oldest first")


@router.get(
    "/{stream_id}/phase-plane",
    summary="A demon's value map over two sensors (the others held at their last readings), with the trail",
    responses={**NOT_FOUND, **CONFLICT},
)
def get_phase_plane(
    stream_id: StreamId,
    streams: StreamsDep,
    demon: Annotated[str, Query(min_length=1, max_length=64)],
    x: Annotated[str, Query(min_length=1, max_length=80, description="the sensor along x")],
    y: Annotated[str, Query(min_length=1, max_length=80, description="the sensor along y")],
    resolution: Annotated[int, Query(ge=2, le=MAX_PHASE_RESOLUTION)] = 32,
) -> PhasePlaneOut:
    ax, ay, values, trail = streams.get(stream_id).phase_plane(demon, x, y, resolution)
    cells = [[float(v) if np.isfinite(v) else None for v in row] for row in values]
    return PhasePlaneOut(demon=demon, x=AxisOut(sensor=ax.sensor, low=ax.low, high=ax.high),
                         y=AxisOut(sensor=ay.sensor, low=ay.low, high=ay.high), values=cells,
                         trail=trail.tolist())  # fmt: skip


class StreamHistoryOut(Out):
    records: list[int] = Field(description="each row's record number in the stream (0 = the first ever sent)")
    sensors: dict[str, list[float]] = Field(description="sensor -> its reading at each record")
    predictions: dict[str, list[float | None]] = Field(
        description="demon -> its prediction on observing each record (null: not a finite number)"
    )
    returns: dict[str, list[float | None] | None] = Field(
        description="demon -> the discounted return that followed each record, computed afterwards from the "
        "records after it (null where the stream has not gone far enough yet, or a refused record broke it; the "
        "behaviour's return, so the demon's answer only for on-policy questions); null for a demon whose "
        "question reads other demons' predictions"
    )


def _names(text: str | None, default: list[str], field: str) -> list[str]:
    if text is None:
        return default
    names = [n.strip() for n in text.split(",") if n.strip()]
    if not names or len(names) > MAX_HISTORY_SERIES:
        message = f"give 1 to {MAX_HISTORY_SERIES} comma-separated names"
        raise SpecError([FieldProblem(("query", field), message)])
    return names


def _floats(values: np.ndarray) -> list[float | None]:
    return [float(v) if np.isfinite(v) else None for v in values]


@router.get(
    "/{stream_id}/history",
    summary="The recent records' sensors, and each demon's prediction beside the return that followed",
    responses={**NOT_FOUND, **CONFLICT},
)
def get_stream_history(
    stream_id: StreamId,
    streams: StreamsDep,
    sensors: Annotated[str | None, Query(max_length=2000, description="comma-separated (default: the first 4)")] = None,
    demons: Annotated[str | None, Query(max_length=2000, description="comma-separated (default: the first 4)")] = None,
    last: Annotated[int, Query(ge=2, le=HISTORY, description="records, at most")] = 1000,
) -> StreamHistoryOut:
    """The strip chart of the nexting paper: the last `last` good records (the server keeps the last 2,000, fewer
    for Hordes of more than 2,000 demons) with each chosen demon's prediction made at the time beside the
    realised discounted return computed afterwards from the stream."""
    run = streams.get(stream_id)
    names = run.spec.world.sensor_names()
    history = run.history(_names(sensors, names[:4], "sensors"), _names(demons, run.names[:4], "demons"), last)
    return StreamHistoryOut(
        records=history.numbers.tolist(),
        sensors={s: v.tolist() for s, v in history.sensors.items()},
        predictions={d: _floats(v) for d, v in history.predictions.items()},
        returns={d: None if v is None else _floats(v) for d, v in history.returns.items()},
    )


def _may_push(websocket: WebSocket, access: Access, stream_id: str) -> None:
    """Refuse (close) a WebSocket whose token may not push to the stream run: none on a server with roles
    (4401; a wrong or revoked one was closed with 4401 on accepting), a viewer's or another student's (4403)."""
    principal = websocket.state.principal
    if principal is None:
        raise WebSocketException(StreamClose.UNAUTHORIZED, NO_TOKEN)
    try:
        access.check(principal, "stream", stream_id)
    except ForbiddenError as exc:
        raise WebSocketException(StreamClose.FORBIDDEN, close_reason(str(exc))) from None


def _items(message: Mapping[str, Any]) -> list[Any]:
    """A message's records. Raises ValueError for a binary frame, text that is not JSON, JSON nested deeper
    than a REST body may be, or a batch that is too large."""
    text = message.get("text")
    if text is None:
        raise ValueError("a binary frame: send each message as JSON text")
    try:
        data = json.loads(text)
    except RecursionError:  # deeper than Python's parser goes
        raise ValueError(f"nested more than {MAX_JSON_DEPTH} levels deep") from None
    problem = json_problem(data)
    if problem is not None:
        raise ValueError(problem["msg"])
    if isinstance(data, dict) and set(data) == {"records"} and isinstance(data["records"], list):
        if len(data["records"]) > MAX_RECORDS_PER_BATCH:
            raise ValueError(f"at most {MAX_RECORDS_PER_BATCH} records a message (this one has {len(data['records'])})")
        return list(data["records"])
    return [data]


async def _learn(queue: asyncio.Queue[list[Any] | None], run: StreamRun, websocket: WebSocket) -> None:
    """Learn the messages of `queue` (what waits, up to MAX_RECORDS_PER_BATCH records, in one go) until None;
    answer each batch with its refusals and a `learned` message."""
    while True:
        items = await queue.get()
        if items is None:
            return
        while not queue.empty() and len(items) < MAX_RECORDS_PER_BATCH:
            more = queue.get_nowait()
            if more is None:
                await queue.put(None)
                break
            items = items + more
        try:
            result = await asyncio.to_thread(run.push, items)
        except RunError as exc:  # its worker died: say so, and end the stream
            await websocket.send_json({"type": "error", "index": None, "field": "run", "message": str(exc)})
            return
        for refusal in result.refused:
            await websocket.send_json({"type": "error", "index": refusal.index, "field": refusal.field,
                                       "message": refusal.message})  # fmt: skip
        await websocket.send_json({"type": "learned", "received": result.received, "learned": result.learned,
                                   "predictions": result.predictions.tolist()})  # fmt: skip


@router.websocket("/{stream_id}/records")
async def stream_records(websocket: AcceptedSocket, stream_id: str, access: AccessDep, streams: StreamsDep) -> None:
    """Push records, read predictions (see the module). Close codes (StreamClose): 4404 unknown stream run,
    4401 no token, or a wrong or revoked one (when HORDE_TOKEN is set: `Authorization: Bearer` or `?token=`),
    4403 a viewer's token or another student's stream run, 1008 a page of another site, 4410 the stream run
    was deleted (what was pushed after that is not learned). The upgrade is accepted before any of these, so
    that the client sees the code."""
    if websocket.state.principal is None:
        raise WebSocketException(StreamClose.UNAUTHORIZED, NO_TOKEN)
    try:
        run = streams.get(stream_id)
    except NotFoundError:
        raise WebSocketException(StreamClose.NOT_FOUND, close_reason(f"no stream run {stream_id!r}")) from None
    _may_push(websocket, access, stream_id)
    await websocket.send_json({"type": "hello", "sensors": run.spec.world.sensor_names(),
                               "actions": run.spec.world.num_actions(), "demons": run.names})  # fmt: skip
    queue: asyncio.Queue[list[Any] | None] = asyncio.Queue(maxsize=QUEUE)
    learner = asyncio.create_task(_learn(queue, run, websocket))
    deleted = False
    try:
        while not learner.done():
            message = await websocket.receive()
            if message["type"] == "websocket.disconnect":
                break
            try:
                items = _items(message)
            except ValueError as exc:  # json.JSONDecodeError is one; the message is refused whole, none learned
                problem = f"not JSON: {exc}" if isinstance(exc, json.JSONDecodeError) else str(exc)
                await websocket.send_json({"type": "error", "index": None, "field": "message", "message": problem})
                continue
            if not streams.holds(run):  # deleted meanwhile: this message is not learned, nor any later one
                deleted = True
                break
            await queue.put(items)  # waits while QUEUE messages are unlearned: back-pressure
    except WebSocketDisconnect:
        pass
    finally:
        if not learner.done():
            await queue.put(None)
            with contextlib.suppress(Exception):
                await learner
        if deleted:
            with contextlib.suppress(Exception):
                await websocket.close(code=StreamClose.RUN_DELETED, reason=f"stream run {run.id!r} was deleted")
