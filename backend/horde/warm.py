"""Compile the engine's kernels into numba's on-disk cache for every dtype, one after the other, in this process:
`python -m horde.warm`.

On a cold cache the engine's loop takes about two minutes of one core to compile, once per dtype;
every later process loads it from the cache in about a second. `make test` runs this first, while it lints and
type-checks, because the tests then run in several processes at once: numba's cache is safe to read from many
processes, but two processes compiling the same function at once can overwrite each other's cache entries (it
numbers a function's entries by how many its index held when it read it), and a process that later loads the
wrong entry crashes. Once this has run, nothing is compiled twice.
"""

from __future__ import annotations

import sys
import time
from typing import get_args

from horde.core.batch import warm_up
from horde.scenarios import find_scenario
from horde.spec.demons import Dtype

SCENARIO = "experiment1"  # one grid run compiles the whole loop: a Gymnasium or stream world reuses it


def main() -> None:
    for dtype in get_args(Dtype):
        began = time.monotonic()
        spec = find_scenario(SCENARIO)
        spec = spec.model_copy(update={"learning": spec.learning.model_copy(update={"dtype": dtype})})
        warm_up(spec)
        print(f"horde.warm: the engine's kernels in {dtype}: {time.monotonic() - began:.1f} s", file=sys.stderr)


if __name__ == "__main__":
    main()
