"""The error responses that routes document in the OpenAPI schema, and the handlers that produce them."""

from __future__ import annotations

from typing import Any

from fastapi import FastAPI, Request
from fastapi.exception_handlers import http_exception_handler
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse, Response
from starlette.exceptions import HTTPException as StarletteHTTPException
from starlette.routing import Match
from starlette.types import Scope

from horde.runs.access import ForbiddenError, UnauthorizedError
from horde.runs.errors import BusyError, ConflictError, NotFoundError, RunError, SaveError, SpecError
from horde.server.guard import validation_body, validation_error
from horde.server.schemas import ErrorOut

Responses = dict[int | str, dict[str, Any]]

BAD_BODY: Responses = {
    400: {"model": ErrorOut, "description": "The body cannot be parsed (not JSON, not UTF-8)"},
    413: {"model": ErrorOut, "description": "The body is larger than the server accepts (HORDE_MAX_BODY)"},
}
NOT_FOUND: Responses = {404: {"model": ErrorOut, "description": "Unknown run, demon, world or scenario"}}
CONFLICT: Responses = {409: {"model": ErrorOut, "description": "The resource's state forbids this request"}}
UNAUTHORIZED: Responses = {
    401: {
        "model": ErrorOut,
        "description": "HORDE_TOKEN is set and the bearer token is missing, not this server's, or revoked",
    }
}
FORBIDDEN: Responses = {
    403: {
        "model": ErrorOut,
        "description": "The token's role may not do this: a viewer changes nothing; a student changes only what "
        "they created (the detail names the owner); only the teacher manages tokens",
    }
}
BUSY: Responses = {
    429: {"model": ErrorOut, "description": "Too many evaluations or protocols at once, or the run is busy"}
}

NOT_SAVED: Responses = {
    503: {
        "model": ErrorOut,
        "description": "Not saved: the store could not write (say, the disk is full); the detail says why and "
        "whether the change holds (a run's command) or was not made (a new run or world)",
    }
}

STATUS: dict[type[RunError], int] = {
    UnauthorizedError: 401,
    ForbiddenError: 403,
    NotFoundError: 404,
    ConflictError: 409,
    BusyError: 429,
    SaveError: 503,
}


async def _run_error(request: Request, exc: Exception) -> Response:
    if isinstance(exc, SpecError):
        problems = [{"loc": list(p.loc), "msg": p.msg, "type": p.type} for p in exc.problems]
        return Response(validation_body(problems), status_code=422, media_type="application/json")
    status = next((code for kind, code in STATUS.items() if isinstance(exc, kind)), 409)
    headers = {"WWW-Authenticate": "Bearer"} if status == 401 else None
    return JSONResponse(status_code=status, content={"detail": str(exc)}, headers=headers)


METHODS = ("GET", "HEAD", "POST", "PUT", "PATCH", "DELETE")  # what the API's routes answer


def allowed_methods(app: FastAPI, scope: Scope) -> list[str]:
    """The methods some route of `app` answers at the request's path: each is tried as the router would."""
    return [
        method
        for method in METHODS
        if any(route.matches({**scope, "method": method})[0] == Match.FULL for route in app.router.routes)
    ]


async def _http_error(request: Request, exc: Exception) -> Response:
    """FastAPI's answer to an HTTP exception, but a 405's `Allow` lists the methods of every route at the path
    (Starlette names only those of the first route it tried)."""
    assert isinstance(exc, StarletteHTTPException)
    if exc.status_code == 405:
        allow = ", ".join(allowed_methods(request.app, request.scope))
        exc = StarletteHTTPException(405, exc.detail, headers={**(exc.headers or {}), "Allow": allow})
    return await http_exception_handler(request, exc)


def add_error_handlers(app: FastAPI) -> None:
    """401, 403, 404, 409, 429, 503 with {"detail": message}; 422 in FastAPI's {"detail": [{loc, msg, type}]} form,
    bounded; 405 with the path's every method in `Allow`."""
    app.add_exception_handler(RunError, _run_error)
    app.add_exception_handler(RequestValidationError, validation_error)
    app.add_exception_handler(StarletteHTTPException, _http_error)
