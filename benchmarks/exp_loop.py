"""What an exp costs inside a loop over many weights, the loop of TIDBD's and Autostep's meta step.

    python -m benchmarks.exp_loop [--count 3660000] [--rounds 2]

Each form is timed in the same compiled loop, a[i] *= exp(u[i]) over `count` numbers (3.66 million: one a
nexting step's weights of x_t, 457 rows x 8000 demons), u uniform in (-0.05, 0.05); best of ten calls after one
that compiles (`step_parts.best_of`), ns a number.
`a[i] *= 1 + u[i]` is the loop's memory alone (24 bytes a number). The C library's `math.exp` is one call a
number; `vector_exp` (engine/fast_exp.py) vectorizes over the whole range; `exp_small` and `exp_tiny` are Autostep's
polynomials for |u| <= 1/16 and 1/100 (learners/adaptive.py). docs/performance.md, "TIDBD's exp, fused".
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable
from functools import partial

import numpy as np
from numba import njit

from benchmarks.step_parts import best_of
from horde.core.engine.fast_exp import vector_exp
from horde.core.learners.adaptive import exp_small, exp_tiny


def _loop(exp: Callable[[float], float]) -> Callable[[np.ndarray, np.ndarray], None]:
    @njit
    def scale(a: np.ndarray, u: np.ndarray) -> None:
        for i in range(a.shape[0]):
            a[i] *= exp(u[i])

    return scale


@njit(inline="always")
def _one_plus(x: float) -> float:
    return 1.0 + x


FORMS = {
    "1 + u (the memory alone)": _loop(_one_plus),
    "math.exp": _loop(math.exp),
    "vector_exp": _loop(vector_exp),
    "exp_small": _loop(exp_small),
    "exp_tiny": _loop(exp_tiny),
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--count", type=int, default=3_660_000)
    parser.add_argument("--rounds", type=int, default=2)
    args = parser.parse_args()
    u = np.random.default_rng(0).uniform(-0.05, 0.05, args.count)
    print("| round | " + " | ".join(FORMS) + " |\n|---|" + "---|" * len(FORMS))
    for round_ in range(1, args.rounds + 1):
        calls = [partial(scale, np.ones(args.count), u) for scale in FORMS.values()]
        times = [1e6 * best_of(call, repeats=10, count=1) / args.count for call in calls]
        print(f"| {round_} | " + " | ".join(f"{t:.2f}" for t in times) + " |", flush=True)
    print(f"ns a number, best of 10 loops over {args.count:,} numbers; one thread")


if __name__ == "__main__":
    main()
