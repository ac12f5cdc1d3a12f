"""Errors of the run layer; the server maps each kind to one HTTP status (404, 409, 422, 429, 503)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from pydantic import ValidationError


class RunError(Exception):
    """Base class: a request the run layer refuses, with a message meant for the user."""


class NotFoundError(RunError):
    """An unknown run, demon, world or scenario (HTTP 404)."""


class ConflictError(RunError):
    """A request that the resource's current state forbids (HTTP 409)."""


class BusyError(RunError):
    """Too much work of one kind in flight; try again later (HTTP 429)."""


class SaveError(RunError):
    """The run's state changed but could not be written to the store (HTTP 503).

    The change itself holds (a paused run stays paused); the message says what was done and why it
    was not saved, so that a client never reads a success that a restart would undo.
    """


class StoreWriteError(SaveError):
    """The store refused a write (the disk is full, the file read-only, an I/O error): nothing of it was written
    (HTTP 503, its message saying why: "the store could not write: database or disk is full")."""


class StoreOpenError(Exception):
    """The data directory cannot hold the store (read-only, not a directory, ...): the server cannot start."""


@dataclass(frozen=True)
class FieldProblem:
    """One invalid field: where it is (as FastAPI writes locations) and what is wrong."""

    loc: tuple[str | int, ...]
    msg: str
    type: str = "value_error"


class SpecError(RunError):
    """An invalid spec, with every problem located by field (HTTP 422)."""

    def __init__(self, problems: Sequence[FieldProblem]) -> None:
        self.problems = list(problems)
        super().__init__("; ".join(f"{'.'.join(map(str, p.loc))}: {p.msg}" for p in self.problems))

    @classmethod
    def at(cls, loc: tuple[str | int, ...], msg: str) -> SpecError:
        """One problem at one location."""
        return cls([FieldProblem(loc, msg)])

    @classmethod
    def from_validation(cls, exc: ValidationError, prefix: tuple[str | int, ...] = ()) -> SpecError:
        """Pydantic's errors, their locations prefixed (e.g. with ("body",))."""
        return cls([FieldProblem((*prefix, *e["loc"]), e["msg"], e["type"]) for e in exc.errors()])
