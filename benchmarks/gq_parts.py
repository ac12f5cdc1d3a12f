"""Where a control GQ step goes: ms a step of each part of GQ's kernel, on one thread, timed where it runs.

    python -m benchmarks.gq_parts [--demons 2000] [--steps 200] [--dtype float64,float32]

The control workload (`benchmarks.workloads`) runs 150 steps; then `--steps` transitions are recorded (features,
action, b(a_t | s_t), cumulants, outcomes, continuations) and replayed through GQ's `prepare`, `columns` and
`finish` in one compiled loop, with the cycle counter read between the parts (`columns` is written out here part
by part, calling the kernel's own helpers, so the numbers are the kernel's). Parts: the merge of the traces
(`prepare`), each action's rows at s_{t+1} paid and read (`pay_and_read`), the target policies and TD errors,
w at x_t, the support pass (`_classes_pass`, with `_gather`), and the rest (the correction owed, the new values,
`observe_range`, `finish`). The whole step through `Simulation.run` is timed beside it: what it has beyond the
parts is the world, the features' coding, the questions and the divergence check.
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
from horde.core.engine.rows import pay_and_read, pay_and_read_four, sum_rows
from horde.core.engine.rows import td_error as td_error_at
from horde.core.engine.values import value_policy
from horde.core.learners import gradient
from horde.core.learners.gradient import _classes_pass, _one_class_pass, at, finish, observe_range, prepare, square
from horde.core.policies import FIXED
from horde.core.simulation import Simulation

PARTS = ("merge", "rows at s_t+1", "policy, delta", "w at x_t", "support pass", "the rest")


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
    """`gradient.columns`, part by part, adding each part's cycles to out[1:5] (out[5]: the rest)."""
    c0 = cycles()
    lo = lay.block_lo[b]
    woff, voff, ncls = lay.woff[b], lay.voff[b], lay.ncls[b]
    db = lay.block_hi[b] - lo
    width = i1 - i0
    own = lay.policy[b] != FIXED
    x_t, v_t, x_tp1, v_tp1, n_s = stp.x_t, stp.v_t, stp.x_tp1, stp.v_tp1, stp.n_s
    theta, w, trace, owed = wts.theta, wts.w, wts.trace, wts.owed
    values, pi_next, ex = scr.values, scr.pi_next, scr.ex
    ad, awd, w_dot_e, w_dot_x = scr.work[0], scr.work[1], scr.work[2], scr.work[3]
    rows, rows_f, dropped = scr.rows, scr.rows_f, scr.counts[1]
    A = dem.q.shape[1]
    shift = stp.action * n_s
    if lay.actions[b] == 4:
        o = lo + i0
        pay_and_read_four(theta, woff + i0, n_s * db, x_t, v_t, x_tp1, v_tp1, db,
                          (owed[0, o : lo + i1], owed[1, o : lo + i1], owed[2, o : lo + i1], owed[3, o : lo + i1]),
                          (values[0, i0:i1], values[1, i0:i1], values[2, i0:i1], values[3, i0:i1]))  # fmt: skip
    else:
        for a in range(lay.actions[b]):
            pay_and_read(theta, woff + a * n_s * db + i0, x_t, v_t, x_tp1, v_tp1, db, owed[a, lo + i0 : lo + i1],
                         values[a, i0:i1])  # fmt: skip
    for a in range(lay.actions[b]):
        for i in range(i0, i1):
            ex[a, i] = 0.0
    c1 = cycles()
    out[1] += c1 - c0
    for i in range(i0, i1):
        d = lo + i
        g1 = cls.gamma_tp1[lay.slot_class[d]]
        if own:
            value_policy(lay.policy[b], values[:, i], lay.temperature[d], lay.epsilon[d], pi_next[:, i])
        else:
            for a in range(A):
                pi_next[a, i] = cls.pi_given[lay.slot_class[d], a]
        v_next = 0.0
        for a in range(A):
            v_next += pi_next[a, i] * values[a, i]
        dl = td_error_at(dem.r[d], dem.z[d], g1, v_next, dem.q[d, stp.action])
        dem.delta[d] = dl
        ad[i] = dem.alpha[d] * dl if dem.alpha[d] != 0.0 else 0.0
        awd[i] = dem.alpha_w[d] * dl if dem.alpha_w[d] != 0.0 else 0.0
        w_dot_e[i] = 0.0
        w_dot_x[i] = 0.0
    c2 = cycles()
    out[2] += c2 - c1
    step_x = w_dot_x[i0:i1]
    sum_rows(w, woff + shift * db + i0, x_t, v_t, db, step_x)
    for i in range(width):
        a_w = dem.alpha_w[lo + i0 + i]
        step_x[i] = step_x[i] * a_w if a_w != 0.0 else 0.0
    end = rows.shape[0] - 1
    for j in range(dropped):
        start = at(woff + rows[end - j] * db + i0)
        f = rows_f[end - j]
        for i in range(width):
            w[start + at(i)] -= f * step_x[i]
    c3 = cycles()
    out[3] += c3 - c2
    if ncls == 1:
        _one_class_pass(b, i0, i1, lay, wts, scr, step_x)
    else:
        _classes_pass(b, i0, i1, lay, wts, stp, scr, step_x, own)
    c4 = cycles()
    out[4] += c4 - c3
    for i in range(i0, i1):
        a_i = dem.alpha[lo + i]
        g1 = cls.gamma_tp1[lay.slot_class[lo + i]]
        w_dot_e[i] = a_i * g1 * (1.0 - lay.lam[b]) * w_dot_e[i] if a_i != 0.0 else 0.0
    own_dot = square(v_tp1)
    for a in range(lay.actions[b]):
        if ncls == 1:
            e_dot_x = 0.0
            for j in range(x_tp1.shape[0]):
                e_dot_x += v_tp1[j] * np.float64(trace[voff + a * n_s + x_tp1[j]])
            for i in range(i0, i1):
                ex[a, i] = e_dot_x
        for i in range(i0, i1):
            o = w_dot_e[i] * pi_next[a, i]
            values[a, i] += ad[i] * ex[a, i] - o * own_dot
            owed[a, lo + i] = o
    observe_range(b, i0, i1, lay, dem, cls, values)
    out[5] += cycles() - c4


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
        finish(b, lay, cls, stp, scr)
        out[5] += cycles() - c2
        out[6] += cycles() - c0


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
    out = np.zeros(7, dtype=np.int64)
    replay(t, b, stream, n_s, True, out)  # compiles, and settles the supports on the stream
    replay(t, b, stream, n_s, False, out)
    best_parts = np.full(7, np.inf)
    best_plain = float("inf")
    for _ in range(repeats):
        for timed in (True, False):
            out[:] = 0
            replay(t, b, stream, n_s, timed, out)
            ms = 1e3 * out / rate / (steps - 1)
            if timed:
                best_parts = np.minimum(best_parts, ms)
            else:
                best_plain = min(best_plain, ms[6])
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
        cells = [dtype, str(support), f"{step:.2f}", f"{plain:.2f}"] + [f"{p:.2f}" for p in parts[:6]]
        print("| " + " | ".join(cells) + f" | {parts[:6].sum():.2f} |", flush=True)


if __name__ == "__main__":
    main()
