"""The wire format of the classroom: tokens (`/api/tokens`), who is asking (`/api/me`), the overview of every
run as a card (`/api/overview`)."""

from __future__ import annotations

from datetime import datetime
from typing import Literal

from pydantic import Field, field_validator

from horde.runs.access import TEACHER
from horde.runs.run_view import RunStatus
from horde.server.schemas import In, MaybeFloat, Out

MAX_TOKEN_NAME = 40  # characters of a token's name: a student's name, shown beside what they make


class TokenIn(In):
    """A token to issue (POST /api/tokens, the teacher's)."""

    role: Literal["student", "viewer"] = Field(
        description="student: creates runs, worlds, studies and changes only those; viewer: changes nothing"
    )
    name: str = Field(
        min_length=1,
        max_length=MAX_TOKEN_NAME,
        pattern=r"^[^\x00-\x1f\x7f]+$",
        description="who holds it (a student's name): shown as the owner of what they make",
    )

    @field_validator("name")
    @classmethod
    def _not_the_teacher(cls, name: str) -> str:
        if name.strip() != name or not name.strip():
            raise ValueError("a name neither starts nor ends with spaces")
        if name.lower() == TEACHER.name:
            raise ValueError("'teacher' names the holder of HORDE_TOKEN; choose the student's or viewer's name")
        return name


class TokenOut(Out):
    id: str = Field(description="the token's id (DELETE /api/tokens/{id} revokes it); never the secret")
    name: str
    role: Literal["student", "viewer"]
    created_at: datetime


class TokenIssuedOut(TokenOut):
    token: str = Field(description="the secret, shown this once (the server keeps only its SHA-256)")
    link: str = Field(description="an invitation: the dashboard's address carrying the token (?token=...)")


class MeOut(Out):
    """Who the request acts as, so that the dashboard shows only the controls that role may use."""

    role: Literal["teacher", "student", "viewer", "anonymous"] = Field(
        description="anonymous: no token on a server with HORDE_TOKEN (reads only)"
    )
    id: str | None = Field(description="the token's id ('teacher' for HORDE_TOKEN's holder), null when anonymous")
    name: str | None
    tokens: bool = Field(description="whether the server has roles (HORDE_TOKEN is set); without, all are teacher")


class SparklineOut(Out):
    """A run's first demons' predictions over its recent history, thinned to a few dozen points."""

    steps: list[int]
    series: dict[str, list[MaybeFloat]] = Field(description="demon name -> prediction at each of `steps`")


class RunCardOut(Out):
    """A run as the Class tab's card shows it."""

    id: str
    name: str | None = Field(description="the run spec's name (its scenario's, unless renamed)")
    owner: str
    status: RunStatus
    episode: int
    step: int
    sparkline: SparklineOut
    updated_at: datetime
