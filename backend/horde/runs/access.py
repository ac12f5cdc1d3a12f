"""Who may change what: the teacher, students and viewers, their tokens, and the owners of things.

Three roles (DESIGN.md section 8):

- the **teacher** holds the server's own HORDE_TOKEN and may change everything;
- a **student** (a token the teacher issued) creates runs, worlds, studies, protocol jobs and stream runs,
  and changes only what they created: another's is read-only to them (ForbiddenError, 403, naming its owner);
- a **viewer** (a token the teacher issued) changes nothing (403).

Without HORDE_TOKEN there are no roles: everyone is the teacher, as before tokens existed (the server binds
loopback unless told otherwise). Reads need no token either way. A token that is not the server's, or that
the teacher revoked, is refused wherever it is presented (UnauthorizedError, 401).

`Access` answers these questions for the API's routes and WebSockets and for the live view's commands alike
(one rule on both ports). It keeps the tokens and owners in memory, loaded from the store at start-up and
written through on every change, so that a check costs a dictionary look-up, not a query.
"""

from __future__ import annotations

import hmac
import threading
from dataclasses import dataclass
from typing import Literal

from horde.runs.errors import ConflictError, NotFoundError, RunError
from horde.runs.owners import Kind, forget_owner, load_owners, set_owner
from horde.runs.tables import Tables
from horde.runs.tokens import IssuedRole, TokenRecord, digest, issue_token, load_tokens, revoke_token

Role = Literal["teacher", "student", "viewer"]
TEACHER_ID = "teacher"  # the owner of what the teacher made (and of everything made before tokens)


class UnauthorizedError(RunError):
    """No token where one is needed, or a token that is not the server's or was revoked (HTTP 401)."""


class ForbiddenError(RunError):
    """A token whose role may not do this: a viewer's change, a student's change of another's thing, a
    token issued by someone other than the teacher (HTTP 403); the message names the rule or the owner."""


@dataclass(frozen=True)
class Principal:
    """Who a request (or a live-view browser) acts as."""

    id: str  # the token's id, or TEACHER_ID
    name: str
    role: Role


TEACHER = Principal(TEACHER_ID, "teacher", "teacher")


class Access:
    """The server's tokens and owners, and the rule over them.

    Args:
        store: where tokens and owners are kept.
        teacher_token: the server's HORDE_TOKEN (None: no roles, everyone is the teacher).
    """

    def __init__(self, store: Tables, teacher_token: str | None) -> None:
        self.store = store
        self._teacher = teacher_token.encode() if teacher_token else None
        self._lock = threading.Lock()
        self._tokens: dict[str, TokenRecord] = {t.id: t for t in load_tokens(store)}
        self._by_digest = {t.digest: t.id for t in self._tokens.values()}
        self._owners = load_owners(store)

    @property
    def required(self) -> bool:
        """Whether the server has roles (HORDE_TOKEN is set)."""
        return self._teacher is not None

    # ------------------------------------------------------------------------------------------
    # Who is asking

    def identify(self, secret: str | None) -> Principal | None:
        """The principal of a token; None for no token on a server with roles (an anonymous reader).

        Raises:
            UnauthorizedError: a token that is not this server's, or one the teacher revoked.
        """
        if self._teacher is None:
            return TEACHER
        if not secret:
            return None
        if hmac.compare_digest(secret.encode(), self._teacher):
            return TEACHER
        with self._lock:
            token = self._tokens.get(self._by_digest.get(digest(secret), ""))
        if token is None:
            raise UnauthorizedError("this token is not one of this server's (the teacher's HORDE_TOKEN or one issued)")
        if token.revoked_at is not None:
            raise UnauthorizedError(f"the token {token.name!r} was revoked by the teacher")
        return Principal(token.id, token.name, token.role)

    def writer(self, secret: str | None) -> Principal:
        """The principal of a request that changes something: a teacher or a student.

        Raises:
            UnauthorizedError: no token, or a wrong or revoked one.
            ForbiddenError: a viewer's token.
        """
        principal = self.identify(secret)
        if principal is None:
            raise UnauthorizedError(
                "this server requires 'Authorization: Bearer <token>' on requests that change anything"
            )
        if principal.role == "viewer":
            raise ForbiddenError(f"{principal.name!r} holds a viewer token: a viewer changes nothing")
        return principal

    # ------------------------------------------------------------------------------------------
    # Owners

    def owner_of(self, kind: Kind, key: str) -> str:
        """The owner's id of a thing (TEACHER_ID when no student made it)."""
        with self._lock:
            return self._owners.get((kind, key), TEACHER_ID)

    def owner_name(self, kind: Kind, key: str) -> str:
        """The owner's name of a thing, as the dashboard shows it ("teacher", or the student's token name)."""
        owner = self.owner_of(kind, key)
        with self._lock:
            token = self._tokens.get(owner)
        return token.name if token is not None else TEACHER.name

    def may_change(self, principal: Principal | None, kind: Kind, key: str) -> bool:
        """Whether `principal` may change the thing (see `check`)."""
        if principal is None or principal.role == "viewer":
            return False
        return principal.role == "teacher" or self.owner_of(kind, key) == principal.id

    def check(self, principal: Principal, kind: Kind, key: str) -> None:
        """Raise unless `principal` may change the thing: the teacher may change all; a student only what
        they created.

        Raises:
            ForbiddenError: a viewer, or a student and another's thing (naming its owner).
        """
        if self.may_change(principal, kind, key):
            return
        if principal.role == "viewer":
            raise ForbiddenError(f"{principal.name!r} holds a viewer token: a viewer changes nothing")
        raise ForbiddenError(
            f"{kind} {key!r} belongs to {self.owner_name(kind, key)!r}: a student changes only what they created"
        )

    def claim(self, principal: Principal, kind: Kind, key: str) -> None:
        """Record `principal` as the owner of a thing it just made (a name reused after a deletion changes
        hands); the teacher's things need no row."""
        with self._lock:
            if principal.id == TEACHER_ID:
                if self._owners.pop((kind, key), None) is None:
                    return
                forget_owner(self.store, kind, key)
                return
            set_owner(self.store, kind, key, principal.id)
            self._owners[(kind, key)] = principal.id

    def forget_kind(self, kind: Kind) -> None:
        """Forget the owners of every thing of a kind (stream runs, which do not outlive the server)."""
        with self._lock:
            for owned in [k for k in self._owners if k[0] == kind]:
                del self._owners[owned]
                forget_owner(self.store, kind, owned[1])

    def release(self, kind: Kind, key: str) -> None:
        """The thing was deleted: forget its owner."""
        with self._lock:
            if self._owners.pop((kind, key), None) is not None:
                forget_owner(self.store, kind, key)

    # ------------------------------------------------------------------------------------------
    # Tokens (the teacher's to issue, list and revoke)

    def _teacher_only(self, principal: Principal, what: str) -> None:
        if self._teacher is None:
            raise ConflictError(
                "this server has no HORDE_TOKEN, so everyone is the teacher: start it with HORDE_TOKEN to issue tokens"
            )
        if principal.role != "teacher":
            raise ForbiddenError(f"only the teacher {what}: {principal.name!r} holds a {principal.role} token")

    def issue(self, principal: Principal, role: IssuedRole, name: str) -> tuple[TokenRecord, str]:
        """A new token for a student or a viewer: its record and its secret (shown once).

        Raises:
            ForbiddenError: `principal` is not the teacher.
            ConflictError: no roles on this server, or a token of that name was issued before (even if revoked).
        """
        self._teacher_only(principal, "issues tokens")
        with self._lock:  # a name stays its first holder's, revoked or not: an owner's name names one token
            if any(t.name == name for t in self._tokens.values()):
                raise ConflictError(f"a token named {name!r} was issued already; choose another name")
            record, secret = issue_token(self.store, role, name)
            self._tokens[record.id] = record
            self._by_digest[record.digest] = record.id
        return record, secret

    def tokens(self, principal: Principal) -> list[TokenRecord]:
        """The tokens not revoked, oldest first (the teacher's to see)."""
        self._teacher_only(principal, "lists tokens")
        with self._lock:
            return [t for t in self._tokens.values() if t.revoked_at is None]

    def revoke(self, principal: Principal, token_id: str) -> TokenRecord:
        """Revoke a token: its holder is refused from now on (what they made stays, under their name).

        Raises:
            NotFoundError: no such token (or revoked already).
        """
        self._teacher_only(principal, "revokes tokens")
        with self._lock:
            token = self._tokens.get(token_id)
            if token is None or token.revoked_at is not None:
                raise NotFoundError(f"no token {token_id!r}")
            revoked = TokenRecord(**{**token.__dict__, "revoked_at": revoke_token(self.store, token_id)})
            self._tokens[token_id] = revoked
        return revoked
