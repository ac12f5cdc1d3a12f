"""Compile the engine's kernels into numba's on-disk cache, one dtype after the other, in this process:
`python -m horde.warm [float64] [float32]` (both when none is named).

On a cold cache the engine's loop takes about three minutes of one core to compile, once per dtype;
every later process loads it from the cache in about a second. `make test` compiles each dtype in a process of
its own while it lints and type-checks, because the tests then run in two processes at once, and each would
otherwise compile the same kernels (two processes may compile at once safely, `horde.core._locked_cache_saves`,
but each pays the minutes).
"""

from __future__ import annotations

import sys
import time
from typing import get_args

from horde.core.batch import warm_up
from horde.scenarios import find_scenario
from horde.spec.demons import Dtype

SCENARIO = "experiment1"  # one grid run compiles the whole loop: a Gymnasium or stream world reuses it


def main(argv: list[str] | None = None) -> None:
    dtypes = get_args(Dtype)
    chosen = sys.argv[1:] if argv is None else argv
    unknown = [name for name in chosen if name not in dtypes]
    if unknown:
        raise SystemExit(f"horde.warm: {unknown[0]!r} is not a dtype; choose from {', '.join(dtypes)}")
    for dtype in chosen or dtypes:
        began = time.monotonic()
        spec = find_scenario(SCENARIO)
        spec = spec.model_copy(update={"learning": spec.learning.model_copy(update={"dtype": dtype})})
        warm_up(spec)
        print(f"horde.warm: the engine's kernels in {dtype}: {time.monotonic() - began:.1f} s", file=sys.stderr)


if __name__ == "__main__":
    main()
