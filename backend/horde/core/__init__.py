"""The learning engine (numba). Its compiled kernels are cached on disk per version of this folder's sources.

numba keys a cached function by its own file only: `engine.loop.run` compiled with the kernels of
`learners/gradient.py` would be loaded unchanged after an edit of `gradient.py` alone, with the old kernels
inside. So the cache lives in a folder named after a digest of every source file here and below (unless
NUMBA_CACHE_DIR says otherwise), and any edit starts a fresh one.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

import numba


def _cache_folder() -> None:
    if os.environ.get("NUMBA_CACHE_DIR"):
        return
    here = Path(__file__).parent
    digest = hashlib.sha256()
    for path in sorted(here.rglob("*.py")):
        digest.update(path.relative_to(here).as_posix().encode() + b"\0" + path.read_bytes())
    numba.config.CACHE_DIR = str(here / "__pycache__" / f"numba-{digest.hexdigest()[:16]}")  # type: ignore[attr-defined]


_cache_folder()
