"""The classroom's tokens: POST|GET /api/tokens, DELETE /api/tokens/{id} (the teacher's), GET /api/me (anyone's).

The teacher (the holder of HORDE_TOKEN) issues a token for a student or a viewer; its secret is shown once, with
an invitation link that carries it (the dashboard at `/?token=...` keeps it for its tab and drops it from the
address). Tokens are stored hashed (runs/tokens.py); revoking one refuses its holder from then on (401) while
what they made keeps their name. Without HORDE_TOKEN there are no roles: issuing is a 409.
"""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Path, Request, status

from horde.runs.access import UnauthorizedError
from horde.runs.tokens import TokenRecord
from horde.server.class_schemas import MeOut, TokenIn, TokenIssuedOut, TokenOut
from horde.server.convert import timestamp
from horde.server.deps import AccessDep, PrincipalDep, WriterDep, write_router
from horde.server.responses import BAD_BODY, CONFLICT, FORBIDDEN, NOT_FOUND, UNAUTHORIZED

router = APIRouter(prefix="/tokens", tags=["classroom"])
writes = write_router(router)
me_router = APIRouter(prefix="/me", tags=["classroom"])

TokenId = Annotated[str, Path(min_length=1, max_length=64, description="the token's id")]


def _out(record: TokenRecord) -> TokenOut:
    return TokenOut(id=record.id, name=record.name, role=record.role, created_at=timestamp(record.created_at))


@writes.post(
    "",
    summary="Issue a token for a student or a viewer (the teacher's)",
    status_code=status.HTTP_201_CREATED,
    responses={**BAD_BODY, **CONFLICT},
)
def issue_token(body: TokenIn, me: WriterDep, access: AccessDep, request: Request) -> TokenIssuedOut:
    """403 unless the requester holds HORDE_TOKEN; 409 on a server without HORDE_TOKEN, or when a token of that
    name was issued before (a name names one holder, as the owner of what they make, even once revoked); 422 for
    an unknown role or a name that is empty, too long or 'teacher'."""
    record, secret = access.issue(me, body.role, body.name)
    link = f"{str(request.base_url).rstrip('/')}/?token={secret}"
    return TokenIssuedOut(**_out(record).model_dump(), token=secret, link=link)


@router.get("", summary="The tokens in use (the teacher's)", responses={**UNAUTHORIZED, **FORBIDDEN, **CONFLICT})
def list_tokens(me: PrincipalDep, access: AccessDep) -> list[TokenOut]:
    """Their ids, names and roles, never their secrets. 401 without a token, 403 for a student's or viewer's."""
    if me is None:
        raise UnauthorizedError("listing tokens needs the teacher's token ('Authorization: Bearer <HORDE_TOKEN>')")
    return [_out(t) for t in access.tokens(me)]


@writes.delete("/{token_id}", summary="Revoke a token (the teacher's)", responses={**NOT_FOUND, **CONFLICT})
def revoke_token(token_id: TokenId, me: WriterDep, access: AccessDep) -> TokenOut:
    """Its holder is refused from now on (401), on the API, its WebSockets and the live view; what they made
    stays, under their name. 404 for an unknown or already revoked token."""
    return _out(access.revoke(me, token_id))


@me_router.get("", summary="Who this request acts as (its token's role)", responses=UNAUTHORIZED)
def who_am_i(me: PrincipalDep, access: AccessDep) -> MeOut:
    """401 for a token that is not this server's or was revoked (the dashboard then drops it)."""
    if me is None:
        return MeOut(role="anonymous", id=None, name=None, tokens=access.required)
    return MeOut(role=me.role, id=me.id, name=me.name, tokens=access.required)
