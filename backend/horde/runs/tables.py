"""What a module that keeps a table of its own in the store (evaluations, owners, tokens) needs of it.

Those modules hand their `CREATE TABLE` statements to the store (runs/store.py reads them when it opens the
database) and use it through this protocol, so that they do not import the store back.
"""

from __future__ import annotations

from typing import Any, Protocol


class Tables(Protocol):
    """The store's `read` and `write` (see `horde.runs.store.Store`)."""

    def read(self, sql: str, args: tuple[object, ...] = ()) -> list[Any]: ...

    def write(self, sql: str, args: tuple[object, ...] = ()) -> int: ...
