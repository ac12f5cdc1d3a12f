"""The tokens the teacher issues (a student's or a viewer's), stored hashed in the store's database.

A token is a random secret shown once, when it is issued; the store keeps its SHA-256 (a secret of
192 random bits needs no slow hash: nothing can be guessed from the digest), its role, its name and
when it was issued and revoked. A revoked token keeps its row, so that what its holder made still
names its owner, and a request with it is told that it was revoked.
"""

from __future__ import annotations

import hashlib
import secrets
import time
from dataclasses import dataclass
from typing import Literal

from horde.runs.tables import Tables

IssuedRole = Literal["student", "viewer"]
TOKEN_PREFIX = "hl_"  # a Horde Lab token, recognisable in a log or a paste

TOKEN_SCHEMA = """
CREATE TABLE IF NOT EXISTS tokens (
    id TEXT PRIMARY KEY,
    name TEXT NOT NULL,
    role TEXT NOT NULL,
    digest TEXT NOT NULL UNIQUE,
    created_at REAL NOT NULL,
    revoked_at REAL
);
"""


@dataclass(frozen=True)
class TokenRecord:
    id: str
    name: str
    role: IssuedRole
    digest: str  # SHA-256 of the secret, hex
    created_at: float
    revoked_at: float | None


def digest(secret: str) -> str:
    """The stored form of a secret."""
    return hashlib.sha256(secret.encode()).hexdigest()


def load_tokens(store: Tables) -> list[TokenRecord]:
    """Every token ever issued (revoked ones too), oldest first."""
    rows = store.read("SELECT id, name, role, digest, created_at, revoked_at FROM tokens ORDER BY created_at")
    return [TokenRecord(*row) for row in rows]


def issue_token(store: Tables, role: IssuedRole, name: str) -> tuple[TokenRecord, str]:
    """A new token: its record and its secret (shown once; only its digest is stored)."""
    secret = TOKEN_PREFIX + secrets.token_urlsafe(24)
    record = TokenRecord(secrets.token_hex(4), name, role, digest(secret), time.time(), None)
    store.write(
        "INSERT INTO tokens VALUES (?, ?, ?, ?, ?, ?)",
        (record.id, record.name, record.role, record.digest, record.created_at, None),
    )
    return record, secret


def revoke_token(store: Tables, token_id: str) -> float:
    """Revoke a token (its row stays); the time it was revoked."""
    now = time.time()
    store.write("UPDATE tokens SET revoked_at = ? WHERE id = ? AND revoked_at IS NULL", (now, token_id))
    return now
