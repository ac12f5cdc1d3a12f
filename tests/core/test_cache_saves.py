"""Two processes compiling one cached function at once keep both entries (`horde.core._locked_cache_saves`).

numba's save reads the function's index, picks the first free entry number and writes the index and the entry.
Each process here is made to pause after that read (a second), so without the lock both pick entry 1: the index
ends with one of the two signatures, and its entry may be the other's code.
"""

from __future__ import annotations

import os
import pickle
import subprocess
import sys
import time
from pathlib import Path

COMPILE = """
import sys, time
from pathlib import Path
import horde.core  # the lock
from numba.core import caching
read = caching.IndexDataCacheFile._load_index
def slow_read(self):
    overloads = read(self)
    time.sleep(1.0)  # between reading the index and writing it: where two saves interleave
    return overloads
caching.IndexDataCacheFile._load_index = slow_read
sys.path.insert(0, sys.argv[1])
go = Path(sys.argv[1]) / "go"
deadline = time.monotonic() + 60
while not go.exists() and time.monotonic() < deadline:
    time.sleep(0.01)
import twice
print(twice.plus_one(1.5 if sys.argv[2] == "float" else 1))
"""

MODULE = """
from numba import njit

@njit(cache=True)
def plus_one(x):
    return x + 1
"""


def test_two_processes_compiling_one_function_keep_both_entries(tmp_path: Path) -> None:
    (tmp_path / "twice.py").write_text(MODULE)
    cache = tmp_path / "cache"
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache)}
    pipes = {"stdout": subprocess.PIPE, "stderr": subprocess.PIPE, "text": True}
    procs = [subprocess.Popen([sys.executable, "-c", COMPILE, str(tmp_path), kind], env=env, **pipes)
             for kind in ("float", "int")]  # fmt: skip
    try:
        time.sleep(0.5)  # both import numba before they may compile (an ordering, not a timing assertion)
        (tmp_path / "go").touch()
        outputs = [p.communicate(timeout=120) for p in procs]
    finally:
        for p in procs:  # ours, by their ids, if a wait above ran out
            if p.poll() is None:
                p.kill()
                p.wait(timeout=10)
    assert [p.returncode for p in procs] == [0, 0], outputs
    assert [out.strip() for out, _ in outputs] == ["2.5", "2"]

    (index,) = cache.rglob("twice.plus_one-*.nbi")
    with index.open("rb") as f:
        pickle.load(f)  # numba's version
        _, overloads = pickle.loads(f.read())
    assert len(overloads) == 2, overloads
    assert len(set(overloads.values())) == 2, f"two signatures share one entry: {overloads}"

    # a third process loads each signature's own code
    check = (
        "import sys; sys.path.insert(0, sys.argv[1]); import horde.core, twice; print(twice.plus_one(1.5), "
        "twice.plus_one(1))"
    )
    out = subprocess.run([sys.executable, "-c", check, str(tmp_path)], env=env, capture_output=True, text=True,
                         timeout=120, check=True)  # fmt: skip
    assert out.stdout.split() == ["2.5", "2"]
