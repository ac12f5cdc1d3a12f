"""Bounded work per request: a body size limit, a nesting limit checked before validation, short 422s.

`BodyGuard` is a pure ASGI middleware in front of the API. For every request with a body it

- refuses a body larger than the limit with 413 (checked on `Content-Length`, and again while the
  body streams in, so a chunked body cannot get past it); the snapshot imports (`IMPORT_PATHS`) have
  their own, larger limit, since a snapshot carries weight arrays;
- parses a JSON body once, in a worker thread when it is large, and refuses one nested deeper than
  `MAX_JSON_DEPTH` (or with a container wider than `MAX_JSON_WIDTH`) with a 422 naming where, before
  pydantic walks it: a union validated level by level on deep input multiplies its errors, and a
  300-level expression used to yield 3,818 errors and a 17 MB response.

`validate_off_loop` moves the parsing, validation and handling of every request with a body off the
server's event loop (a valid spec of thousands of demons takes a second to validate).

`validation_error` replaces FastAPI's handler of request validation errors: at most `MAX_ERRORS`
problems, each with its location, message and type but never the input it was given (the input made
responses large, and a non-finite number in it made the encoder fail with a 500), encoded in a worker
thread.
"""

from __future__ import annotations

import asyncio
import json
import weakref
from collections.abc import Awaitable, Callable, MutableMapping
from typing import Any

import anyio
from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import Response
from fastapi.routing import APIRoute
from starlette.routing import request_response

Scope = MutableMapping[str, Any]
Message = MutableMapping[str, Any]
Receive = Callable[[], Awaitable[Message]]
Send = Callable[[Message], Awaitable[None]]
ASGIApp = Callable[[Scope, Receive, Send], Awaitable[None]]

MAX_JSON_DEPTH = 48  # objects and lists inside each other (a deep expression is refused by the spec first)
MAX_JSON_WIDTH = 20_000  # keys of one object or items of one list
MAX_ERRORS = 20  # problems listed in one 422
MAX_MSG_CHARS = 300  # characters of one problem's message
THREAD_BYTES = 64 * 1024  # bodies larger than this are parsed in a worker thread
IMPORT_PATHS = frozenset({"/api/runs/import", "/api/streams/import"})  # bodies up to max_import_body
REQUEST_THREADS = 4  # requests with a body handled in worker threads at once (WorkLimiter)


def _problem(loc: list[str | int], msg: str, kind: str) -> dict[str, Any]:
    return {"loc": loc, "msg": msg, "type": kind}


def json_problem(
    data: Any, max_depth: int = MAX_JSON_DEPTH, max_width: int = MAX_JSON_WIDTH, max_demons: int | None = None
) -> dict[str, Any] | None:
    """The first place where parsed JSON is nested too deep, a container is too wide, or a list of
    `demons` is longer than the server runs, else None.

    Iterative (an explicit stack), so a deep document cannot exhaust Python's recursion limit here.
    """
    stack: list[tuple[Any, list[str | int]]] = [(data, ["body"])]
    while stack:
        value, loc = stack.pop()
        if isinstance(value, dict | list):
            depth = len(loc)  # "body" counts as the first level
            if depth > max_depth:
                return _problem(loc[:max_depth], f"nested more than {max_depth} levels deep", "too_deep")
            if len(value) > max_width:
                return _problem(loc, f"more than {max_width} items", "too_wide")
            if max_demons is not None and loc[-1] == "demons" and isinstance(value, list) and len(value) > max_demons:
                return _problem(loc, f"at most {max_demons} demons per run (got {len(value)})", "too_long")
            items = value.items() if isinstance(value, dict) else enumerate(value)
            stack.extend((item, [*loc, key]) for key, item in items)
    return None


def _check_json(body: bytes, max_demons: int | None) -> dict[str, Any] | None:
    try:
        data = json.loads(body)
    except RecursionError:
        return _problem(["body"], f"nested more than {MAX_JSON_DEPTH} levels deep", "too_deep")
    except ValueError:
        return None  # FastAPI answers malformed JSON itself (400)
    return json_problem(data, max_demons=max_demons)


async def _send_json(send: Send, status: int, content: Any, close: bool = False) -> None:
    body = json.dumps(content).encode()
    headers = [(b"content-type", b"application/json"), (b"content-length", str(len(body)).encode())]
    if close:  # the rest of a body too large is not read: end the connection instead of receiving it
        headers.append((b"connection", b"close"))
    await send({"type": "http.response.start", "status": status, "headers": headers})
    await send({"type": "http.response.body", "body": body})


class BodyGuard:
    """ASGI middleware: body size and nesting limits for the API (see the module docstring).

    Args:
        app: the application behind it.
        max_body: bytes of a request body at most (413 beyond).
        max_import_body: bytes of a snapshot import (`IMPORT_PATHS`) at most.
        max_demons: demons of one run at most: a longer `demons` list is refused before validation.
    """

    def __init__(self, app: ASGIApp, max_body: int, max_import_body: int, max_demons: int | None = None) -> None:
        self.app = app
        self.max_body = max_body
        self.max_import_body = max_import_body
        self.max_demons = max_demons

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http" or scope["method"] in ("GET", "HEAD", "OPTIONS"):
            await self.app(scope, receive, send)
            return
        limit = self.max_import_body if scope["path"] in IMPORT_PATHS else self.max_body
        too_large = {"detail": f"the request body is larger than this server accepts ({limit} bytes)"}
        headers = dict(scope.get("headers") or [])
        declared = headers.get(b"content-length", b"")
        if declared.isdigit() and int(declared) > limit:
            await _send_json(send, 413, too_large, close=True)
            return
        chunks: list[bytes] = []
        size = 0
        more = True
        while more:
            message = await receive()
            if message["type"] == "http.disconnect":
                return
            chunk = message.get("body", b"")
            size += len(chunk)
            if size > limit:
                await _send_json(send, 413, too_large, close=True)
                return
            chunks.append(chunk)
            more = message.get("more_body", False)
        body = b"".join(chunks)
        if body and b"json" in headers.get(b"content-type", b""):
            if len(body) > THREAD_BYTES:
                problem = await anyio.to_thread.run_sync(_check_json, body, self.max_demons, limiter=REQUEST_WORK.get())
            else:
                problem = _check_json(body, self.max_demons)
            if problem is not None:
                await _send_json(send, 422, {"detail": [problem]})
                return
        replayed = False

        async def replay() -> Message:
            nonlocal replayed
            if not replayed:
                replayed = True
                return {"type": "http.request", "body": body, "more_body": False}
            return await receive()  # after the body: wait for the disconnect, as the server would

        await self.app(scope, replay, send)


def _short(error: dict[str, Any]) -> dict[str, Any]:
    msg = str(error.get("msg", ""))
    if len(msg) > MAX_MSG_CHARS:
        msg = msg[: MAX_MSG_CHARS - 1] + "…"
    loc = [part if isinstance(part, int) else str(part)[:100] for part in error.get("loc", ())][:MAX_JSON_DEPTH]
    return _problem(loc, msg, str(error.get("type", "value_error")))


def validation_body(errors: list[Any]) -> bytes:
    """The 422 body of a request validation error: the first MAX_ERRORS problems, inputs left out."""
    detail = [_short(e) for e in errors[:MAX_ERRORS]]
    if len(errors) > MAX_ERRORS:
        detail.append(_problem(["body"], f"and {len(errors) - MAX_ERRORS} more problems", "too_many_errors"))
    return json.dumps({"detail": detail}).encode()


async def validation_error(request: Request, exc: Exception) -> Response:
    """FastAPI's 422 for invalid requests, bounded and encoded off the event loop."""
    assert isinstance(exc, RequestValidationError)
    body = await anyio.to_thread.run_sync(validation_body, list(exc.errors()))
    return Response(body, status_code=422, media_type="application/json")


class WorkLimiter:
    """At most `total` requests parse, validate and answer in worker threads at once.

    Why a bound: CPython hands the GIL to one waiting thread at a time. With many request threads busy
    (a burst of large bodies), every time the event loop gives up the GIL for I/O it waits its turn
    behind all of them, and `/api/health` took 150 to 300 ms. Requests past the bound wait (their
    clients see them take longer); the loop competes with at most `total` threads. One limiter per
    event loop, made on first use (anyio's limiters belong to the loop they are made in; tests start
    several servers in one process).
    """

    def __init__(self, total: int) -> None:
        self.total = total
        self._limiters: weakref.WeakKeyDictionary[asyncio.AbstractEventLoop, anyio.CapacityLimiter] = (
            weakref.WeakKeyDictionary()
        )

    def get(self) -> anyio.CapacityLimiter:
        loop = asyncio.get_running_loop()
        limiter = self._limiters.get(loop)
        if limiter is None:
            limiter = self._limiters[loop] = anyio.CapacityLimiter(self.total)
        return limiter


REQUEST_WORK = WorkLimiter(REQUEST_THREADS)


def _off_loop(handler: Callable[[Request], Awaitable[Response]]) -> Callable[[Request], Awaitable[Response]]:
    """The route's handler, run in a worker thread with an event loop of its own once the body is read."""

    async def in_thread(request: Request) -> Response:
        return await handler(request)

    async def handle(request: Request) -> Response:
        await request.body()  # read on the server's loop (the ASGI channel lives there), cached on the request
        return await anyio.to_thread.run_sync(lambda: asyncio.run(in_thread(request)), limiter=REQUEST_WORK.get())

    return handle


def validate_off_loop(app: FastAPI) -> None:
    """Parse, validate and answer every request that carries a body (POST, PUT, PATCH) in a worker thread.

    FastAPI validates a body on the server's event loop; a spec of thousands of demons takes a second of
    pydantic and model validators, during which no other request (not even /api/health) is answered.
    Off the loop, it only competes for the GIL, which the loop gets back within the switch interval.
    """
    for route in app.router.routes:
        if isinstance(route, APIRoute) and (route.methods or set()) & {"POST", "PUT", "PATCH"}:
            route.app = request_response(_off_loop(route.get_route_handler()))
