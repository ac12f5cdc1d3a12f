"""Where a control GQ step goes: ms a step of each part of GQ's kernel, on one thread, timed where it runs.

    python -m benchmarks.gq_parts [--demons 2000] [--steps 200] [--dtype float64,float32]

The control workload (`benchmarks.workloads`) runs 150 steps; then `--steps` transitions are recorded (features,
action, b(a_t | s_t), cumulants, outcomes, continuations) and replayed through GQ's `prepare`, `columns` and
`finish` in one compiled loop, with the cycle counter read between the parts (`columns` is called part by part:
the kernel's own parts, so the numbers are the kernel's). Parts: the merge of the traces (`prepare`), each
action's rows at s_{t+1} paid and read with the target policies and TD errors (`gradient.values_and_errors`),
w at x_t (`gradient.w_at_x`), the support pass (`_classes_pass`), and the rest (`gradient.new_values`: the
correction owed, the new values; `finish`). The whole step through `Simulation.run` is timed beside it: what it
has beyond the parts is the world, the features' coding, the questions and the divergence check.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from llvmlite import ir
from numba import njit
from numba.core import cgutils, types
from numba.extending import intrinsic

from benchmarks import workloads
from benchmarks.bound import spec as bound_spec
from horde.core.engine.layout import Step
from horde.core.engine.loop import R_ACTION, R_BPROB
from horde.core.learners import gradient
from horde.core.learners.gradient import _classes_pass, _one_class_pass, finish, prepare
from horde.core.policies import FIXED
from horde.core.simulation import Simulation

PARTS = ("merge", "rows at s_t+1, policy, delta", "w at x_t", "support pass", "the rest")


@intrinsic
def cycles(typingctx):  # type: ignore[no-untyped-def]
    """The CPU's cycle counter (llvm.readcyclecounter)."""

    def codegen(context, builder, signature, args):  # type: ignore[no-untyped-def]
        fn = cgutils.get_or_insert_function(builder.module, ir.FunctionType(ir.IntType(64), []),
                                            "llvm.readcyclecounter")  # fmt: skip
        return builder.call(fn, [])

    return types.int64(), codegen


@njit
def columns_timed(b, i0, i1, lay, wts, dem, cls, stp, scr, out):  # type: ignore[no-untyped-def]
    """`gradient.columns`, its parts called one by one, adding each part's cycles to out[1:4] (out[4]: the
    rest)."""
    c0 = cycles()
    gradient.values_and_errors(b, i0, i1, lay, wts, dem, cls, stp, scr)
    c1 = cycles()
    out[1] += c1 - c0
    step_x = gradient.w_at_x(b, i0, i1, lay, wts, dem, stp, scr)
    c2 = cycles()
    out[2] += c2 - c1
    if lay.ncls[b] == 1:
        _one_class_pass(b, i0, i1, lay, wts, scr, step_x)
    else:
        _classes_pass(b, i0, i1, lay, wts, stp, scr, step_x, lay.policy[b] != FIXED)
    c3 = cycles()
    out[3] += c3 - c2
    gradient.new_values(b, i0, i1, lay, wts, dem, cls, stp, scr)
    out[4] += cycles() - c3


@njit
def replay(t, b, stream, n_s, timed, out):  # type: ignore[no-untyped-def]
    """Block b learns the recorded transitions (features[i] -> features[i + 1]); out: cycles by part."""
    features, values, counts, actions, b_probs, r, z, gamma_tp1 = stream
    lay, wts, dem, cls, scr = t.lay, t.wts, t.dem, t.cls, t.scr
    db = lay.block_hi[b] - lay.block_lo[b]
    for i in range(features.shape[0] - 1):
        dem.r[:] = r[i + 1]
        dem.z[:] = z[i + 1]
        cls.gamma_tp1[:] = gamma_tp1[i + 1]
        x_t, x_tp1 = features[i, : counts[i]], features[i + 1, : counts[i + 1]]
        stp = Step(x_t, values[i, : counts[i]], x_tp1, values[i + 1, : counts[i + 1]], actions[i + 1],
                   b_probs[i + 1], n_s)  # fmt: skip
        c0 = cycles()
        prepare(b, lay, wts, dem, cls, stp, scr)
        c1 = cycles()
        out[0] += c1 - c0
        if timed:
            columns_timed(b, db - db, db, lay, wts, dem, cls, stp, scr, out)
        else:
            gradient.columns(b, db - db, db, lay, wts, dem, cls, stp, scr)
        c2 = cycles()
        finish(b, lay, wts, cls, stp, scr)
        out[4] += cycles() - c2
        out[5] += cycles() - c0


def cycles_per_second() -> float:
    """The cycle counter's rate, against perf_counter."""
    clock = njit(lambda: cycles())
    clock()
    w0, c0 = time.perf_counter(), clock()
    time.sleep(0.2)
    return (clock() - c0) / (time.perf_counter() - w0)


def measure(demons: int, dtype: str, steps: int, repeats: int) -> tuple[float, float, np.ndarray, int]:
    """(a whole step through `Simulation.run`, ms; the replayed kernel untimed, ms; ms by part; support rows)."""
    sim = Simulation(bound_spec("control-gq", demons, dtype), np.random.default_rng(0))
    sim.with_metrics = False
    sim.threads = 1
    sim.run(150)
    best_step = float("inf")
    for _ in range(3):
        w0 = time.perf_counter()
        sim.run(40)
        best_step = min(best_step, (time.perf_counter() - w0) / 40)
    t = sim.learner.engine.t
    (b,) = np.nonzero(t.lay.learner == gradient.GQ_CODE)[0][:1]
    g = int(t.lay.group[b])
    rec: list[list[np.ndarray]] = [[] for _ in range(8)]
    for _ in range(steps):
        sim.run(1)
        count = int(t.coded.counts[g])
        rec[0].append(t.coded.features[g, :count].copy())
        rec[1].append(t.coded.values[g, :count].copy())
        rec[2].append(count)
        rec[3].append(int(t.agent.result[R_ACTION]))
        rec[4].append(float(t.agent.result[R_BPROB]))
        rec[5].append(t.dem.r.copy())
        rec[6].append(t.dem.z.copy())
        rec[7].append(t.cls.gamma_tp1.copy())
    counts = np.array(rec[2], dtype=np.int64)
    features = np.zeros((steps, int(counts.max())), dtype=np.int64)
    values = np.zeros(features.shape)
    for i in range(steps):
        features[i, : counts[i]] = rec[0][i]
        values[i, : counts[i]] = rec[1][i]
    stream = (features, values, counts, np.array(rec[3], dtype=np.int64), np.array(rec[4]), np.array(rec[5]),
              np.array(rec[6]), np.array(rec[7]))  # fmt: skip
    n_s = int(t.grp.n_s[g])
    rate = cycles_per_second()
    out = np.zeros(len(PARTS) + 1, dtype=np.int64)  # the parts, then the whole
    replay(t, b, stream, n_s, True, out)  # compiles, and settles the supports on the stream
    replay(t, b, stream, n_s, False, out)
    best_parts = np.full(len(PARTS) + 1, np.inf)
    best_plain = float("inf")
    for _ in range(repeats):
        for timed in (True, False):
            out[:] = 0
            replay(t, b, stream, n_s, timed, out)
            ms = 1e3 * out / rate / (steps - 1)
            if timed:
                best_parts = np.minimum(best_parts, ms)
            else:
                best_plain = min(best_plain, ms[-1])
    return 1e3 * best_step, best_plain, best_parts, int(t.wts.nnz[b])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--demons", type=int, default=2000)
    parser.add_argument("--steps", type=int, default=100, help="transitions recorded, then replayed")
    parser.add_argument("--repeats", type=int, default=3, help="replays; each part's best is kept")
    parser.add_argument("--dtype", default="float64,float32")
    args = parser.parse_args()
    _ = workloads
    print("| dtype | support rows | step (Simulation) | kernel (replay) | " + " | ".join(PARTS) + " | parts' sum |")
    print("|---" * (len(PARTS) + 5) + "|")
    for dtype in args.dtype.split(","):
        step, plain, parts, support = measure(args.demons, dtype, args.steps, args.repeats)
        cells = [dtype, str(support), f"{step:.2f}", f"{plain:.2f}"] + [f"{p:.2f}" for p in parts[:-1]]
        print("| " + " | ".join(cells) + f" | {parts[:-1].sum():.2f} |", flush=True)


if __name__ == "__main__":
    main()
