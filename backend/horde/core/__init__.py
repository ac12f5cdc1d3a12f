"""The learning engine (numba). Its compiled kernels are cached on disk per version of this folder's sources.

numba keys a cached function by its own file only: `engine.loop.run` compiled with the kernels of
`learners/gradient.py` would be loaded unchanged after an edit of `gradient.py` alone, with the old kernels
inside. So the cache lives in a folder named after a digest of every source file here and below (unless
NUMBA_CACHE_DIR says otherwise), and any edit starts a fresh one.

Several processes may compile into that cache at once (the test suite's processes, a server's run workers on a
cold cache). numba numbers a function's cache entries by how many its index held when it read it, so two
processes saving entries of one function at once can each write entry N, and the index of one then names the
other's code: a later load of it crashes. `_locked_cache_saves` makes each save (read the index, pick a number,
write the index and the entry) one step under a file lock beside the index.
"""

from __future__ import annotations

import fcntl
import hashlib
import os
from pathlib import Path
from typing import Any

import numba
from numba.core import caching


def _cache_folder() -> None:
    if os.environ.get("NUMBA_CACHE_DIR"):
        return
    here = Path(__file__).parent
    digest = hashlib.sha256()
    for path in sorted(here.rglob("*.py")):
        digest.update(path.relative_to(here).as_posix().encode() + b"\0" + path.read_bytes())
    numba.config.CACHE_DIR = str(here / "__pycache__" / f"numba-{digest.hexdigest()[:16]}")  # type: ignore[attr-defined]


def _locked_cache_saves() -> None:
    unlocked = caching.IndexDataCacheFile.save
    if getattr(unlocked, "horde_locked", False):
        return

    def save(self: Any, key: Any, data: Any) -> None:
        with open(self._index_path + ".lock", "ab") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)  # released when the file closes
            unlocked(self, key, data)

    save.horde_locked = True  # type: ignore[attr-defined]
    caching.IndexDataCacheFile.save = save  # type: ignore[method-assign]


_cache_folder()
_locked_cache_saves()
