"""Who created what: the owner of each run, world, study, protocol job and stream run, in the store.

An owner is a token's id (`runs/tokens.py`); a thing with no row is the teacher's (made with the
server's own HORDE_TOKEN, made before tokens existed, or made on a server without one). The rows are
metadata beside the things, not part of their specs: a run's spec is the same whoever launched it.
Keys are (kind, id); a row is written when a student makes a thing and dropped when the thing is
deleted.
"""

from __future__ import annotations

from typing import Literal

from horde.runs.tables import Tables

Kind = Literal["run", "world", "study", "protocol", "stream"]

OWNER_SCHEMA = """
CREATE TABLE IF NOT EXISTS owners (
    kind TEXT NOT NULL,
    id TEXT NOT NULL,
    owner TEXT NOT NULL,
    PRIMARY KEY (kind, id)
);
"""


def load_owners(store: Tables) -> dict[tuple[str, str], str]:
    """Every stored (kind, id) -> owner."""
    return {(str(kind), str(key)): str(owner) for kind, key, owner in store.read("SELECT kind, id, owner FROM owners")}


def set_owner(store: Tables, kind: Kind, key: str, owner: str) -> None:
    """Record `owner` as the owner of the thing (replacing a previous owner of a thing of that name)."""
    store.write("INSERT OR REPLACE INTO owners VALUES (?, ?, ?)", (kind, key, owner))


def forget_owner(store: Tables, kind: Kind, key: str) -> None:
    """The thing is gone: so is its owner."""
    store.write("DELETE FROM owners WHERE kind = ? AND id = ?", (kind, key))
