"""exp(x) in multiply-adds and bit moves, so that a compiled loop over many weights vectorizes it.

`math.exp` in a numba loop is one call into the C library per number: TIDBD's meta step takes one per weight of
x_t's rows (3.66 million a nexting step), and it cost more than the step's memory traffic (docs/performance.md,
"TIDBD's exp"). `vector_exp` is the textbook reduction: x = k ln 2 + r with k an integer and |r| <= ln 2 / 2,
exp(r) by its Taylor polynomial of degree 12 (the remainder below 2e-16 relative), times 2^k built in the float's
exponent bits. Within 1.5 ulp of `math.exp` over the whole range (tests/core/test_fast_exp.py), with its
overflow to inf above 709.78 and its NaN; below -708 the subnormal results are rounded once, as `math.exp`'s.

The loop is held by its arithmetic, not its memory, so each operation counts:
- The reduction and the polynomial are fused multiply-adds (`fma`, LLVM's llvm.fma: one rounding each, in every
  lane of a vector and in the scalar loop alike, so a weight's number does not depend on where a thread's run of
  columns starts). numba emits a multiply and an add apart: the polynomial was 24 operations, now 12.
- The clamp to [LOWEST, HIGHEST] keeps a NaN, and exp of the clamped argument is already exp's value beyond
  it (inf above, 0 below), so no select after the scaling puts the edges back.
A loop of exp-multiplies takes 0.5 of the time it did (docs/performance.md, "TIDBD's exp, fused").
"""

from __future__ import annotations

import math

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


@intrinsic
def fma(typingctx, a, b, c):
    """a b + c rounded once (llvm.fma.f64: the hardware's fused multiply-add, vectorized with the loop)."""

    def codegen(context, builder, signature, args):
        double = ir.DoubleType()
        fused = builder.module.declare_intrinsic("llvm.fma", [double], ir.FunctionType(double, [double] * 3))
        return builder.call(fused, args)

    return types.float64(types.float64, types.float64, types.float64), codegen


# exp's Taylor coefficients 1 / n!, from n = 12 down to 0: a polynomial of degree d takes the last d + 1
TAYLOR = tuple(1.0 / math.factorial(n) for n in range(12, -1, -1))


@njit(cache=True, inline="always")
def taylor(x, coefficients):
    """The polynomial whose coefficients run from the highest power down, at x: Horner's rule in fused
    multiply-adds (`fma`)."""
    p = coefficients[0]
    for c in coefficients[1:]:
        p = fma(p, x, c)  # type: ignore[call-arg]  # (mypy reads an intrinsic as its typing function)
    return p


@njit(cache=True, inline="always")
def vector_exp(x):
    """exp(x), branch-free but for selects (see the module)."""
    xc = LOWEST if x < LOWEST else (HIGHEST if x > HIGHEST else x)  # a NaN fails both and goes through
    t: float = fma(xc, LOG2E, ROUNDER)  # type: ignore[call-arg]  # (mypy reads an intrinsic as its typing function)
    k = t - ROUNDER  # round(x / ln 2)
    r = fma(-k, LN2_LO, fma(-k, LN2_HI, xc))  # x - k ln 2, ln 2 in two parts
    p = taylor(r, TAYLOR)
    ki = _bits(t) - _bits(ROUNDER)  # k as an integer
    # 2^k in two factors, so that each is a normal float: p 2^(k - 1) 2 overflows exactly where exp does, and
    # p 2^(k + 63) 2^-63 rounds a subnormal result once
    low = ki < 0
    e = ki + 63 if low else ki - 1
    return p * _float((e + 1023) << 52) * (2.0**-63 if low else 2.0)
