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
  columns starts). numba emits a multiply and an add apart: the polynomial was 24 operations, 12 in Horner's
  rule, 15 in the short chain below.
- The clamp to [LOWEST, HIGHEST] keeps a NaN, and exp of the clamped argument is already exp's value beyond
  it (inf above, 0 below), so no select after the scaling puts the edges back.
- The polynomial is evaluated in a short chain (`reduced_exp`): in TIDBD's walk, where the exp sits among the
  weight's update, the loop waits on the chain's latency more than on its operations.
A loop of exp-multiplies takes 0.5 of the time it did (docs/performance.md, "TIDBD's exp, fused"); the short chain
took TIDBD's step from about 18 to about 15.6 ms on an AMD EPYC ("TIDBD's exp in a short chain").
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
INVERSE_FACTORIAL = TAYLOR[::-1]  # 1 / n! at n


@njit(cache=True, inline="always")
def taylor(x, coefficients):
    """The polynomial whose coefficients run from the highest power down, at x: Horner's rule in fused
    multiply-adds (`fma`)."""
    p = coefficients[0]
    for c in coefficients[1:]:
        p = fma(p, x, c)  # type: ignore[call-arg]  # (mypy reads an intrinsic as its typing function)
    return p


@njit(cache=True, inline="always")
def reduced_exp(r):
    """exp(r) for |r| <= ln 2 / 2: its Taylor polynomial of degree 12 as 1 + r (1 + r (1/2 + r Q(r))). The tail Q
    (1/3! + r/4! + ... + r^9/12!) goes by Estrin's scheme: its terms in pairs, the pairs combined over r^2, r^4 and
    r^8, four operations deep where Horner's rule is nine. The head goes by Horner's rule, so that the last rounding
    is Horner's: the tail's own rounding errors reach the result only times |r|^3 <= 0.042 (the same 1.42 ulp at most
    against the C library as Horner's rule throughout, tests/core/test_fast_exp.py)."""
    c = INVERSE_FACTORIAL
    r2 = r * r
    r4 = r2 * r2
    # (mypy reads an intrinsic as its typing function: the ignore below)
    pairs: float = fma(fma(c[6], r, c[5]), r2, fma(c[4], r, c[3]))  # type: ignore[call-arg]
    more = fma(fma(c[10], r, c[9]), r2, fma(c[8], r, c[7]))
    tail = fma(fma(c[12], r, c[11]), r4 * r4, fma(more, r4, pairs))
    return fma(fma(fma(tail, r, c[2]), r, c[1]), r, c[0])


@njit(cache=True, inline="always")
def vector_exp(x):
    """exp(x), branch-free but for selects (see the module)."""
    xc = LOWEST if x < LOWEST else (HIGHEST if x > HIGHEST else x)  # a NaN fails both and goes through
    t: float = fma(xc, LOG2E, ROUNDER)  # type: ignore[call-arg]  # (mypy reads an intrinsic as its typing function)
    k = t - ROUNDER  # round(x / ln 2)
    r = fma(-k, LN2_LO, fma(-k, LN2_HI, xc))  # x - k ln 2, ln 2 in two parts
    p = reduced_exp(r)
    ki = _bits(t) - _bits(ROUNDER)  # k as an integer
    # 2^k in two factors, so that each is a normal float: p 2^(k - 1) 2 overflows exactly where exp does, and
    # p 2^(k + 63) 2^-63 rounds a subnormal result once
    low = ki < 0
    e = ki + 63 if low else ki - 1
    return p * _float((e + 1023) << 52) * (2.0**-63 if low else 2.0)
