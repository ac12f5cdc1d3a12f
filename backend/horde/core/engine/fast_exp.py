"""exp(x) in multiply-adds and bit moves, so that a compiled loop over many weights vectorizes it.

`math.exp` in a numba loop is one call into the C library per number: TIDBD's meta step takes one per weight of
x_t's rows (3.66 million a nexting step), and it cost more than the step's memory traffic (docs/performance.md,
"TIDBD's exp"). `vector_exp` is the textbook reduction: x = k ln 2 + r with k an integer and |r| <= ln 2 / 2,
exp(r) by its Taylor polynomial of degree 12 (the remainder below 2e-16 relative), times 2^k built in the float's
exponent bits. Within 2.2 ulp of `math.exp` over the whole range (tests/core/test_fast_exp.py), with its
overflow to inf above 709.78 and its NaN; below -708 the subnormal results are rounded once, as `math.exp`'s.
"""

from __future__ import annotations

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic

LOG2E = 1.4426950408889634
LN2_HI = 0.6931471803691238  # ln 2's leading bits: k LN2_HI is exact for |k| < 2^11
LN2_LO = 1.9082149292705877e-10  # the rest of ln 2
ROUNDER = 6755399441055744.0  # 1.5 * 2^52: adding it rounds to an integer, which lands in the low bits
LOWEST, HIGHEST = -746.0, 709.8  # beyond these exp is 0 or inf in doubles


@intrinsic
def _bits(typingctx, x):
    """A float64's bits as an int64 (no conversion: the same 64 bits)."""

    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], ir.IntType(64))

    return types.int64(types.float64), codegen


@intrinsic
def _float(typingctx, bits):
    """The float64 whose bits are this int64."""

    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], ir.DoubleType())

    return types.float64(types.int64), codegen


@njit(cache=True, inline="always")
def vector_exp(x):
    """exp(x), branch-free but for selects (see the module)."""
    xc = min(max(x, LOWEST), HIGHEST)
    t = xc * LOG2E + ROUNDER
    k = t - ROUNDER  # round(x / ln 2)
    r = (xc - k * LN2_HI) - k * LN2_LO
    p = 1.0 + r * (1.0 + r * (0.5 + r * (1.0 / 6 + r * (1.0 / 24 + r * (1.0 / 120 + r * (1.0 / 720 + r * (
        1.0 / 5040 + r * (1.0 / 40320 + r * (1.0 / 362880 + r * (1.0 / 3628800 + r * (
            1.0 / 39916800 + r * (1.0 / 479001600))))))))))))  # fmt: skip
    ki = _bits(t) - _bits(ROUNDER)  # type: ignore[call-arg,var-annotated]  # k as an integer (mypy reads an intrinsic as its typing function)
    # 2^k in two factors, so that each is a normal float: p 2^(k - 1) 2 overflows exactly where exp does, and
    # p 2^(k + 63) 2^-63 rounds a subnormal result once
    low = ki < 0
    e = ki + 63 if low else ki - 1
    y = p * _float((e + 1023) << 52) * (2.0**-63 if low else 2.0)
    return y if x == xc else (np.inf if x > 0.0 else (0.0 if x < 0.0 else x))  # (x NaN: NaN)
