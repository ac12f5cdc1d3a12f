"""The thesis loop's GTD block alone: microseconds a step of `gtd_pass`'s prepare, columns and finish.

    python -m benchmarks.thesis_gtd_block [--demons 100] [--steps 3000] [--repeats 20]

`benchmarks.thesis` with 100 demons has one GTD block of 98 demons in 4 trace classes over 29 features (the other
two are GQ's). This records a stream from that loop (the block's active features, each class's importance
ratio and continuation, step by step), then replays it through the block's kernels in one compiled loop, so
that a change to `learners/gtd_pass.py` is timed without the world, the features and GQ around it: the best of
five timings, in CPU microseconds a step. The whole loop's figure is `benchmarks.alternate`'s `thesis:100`; this
one is what moved it in docs/performance.md ("The thesis loop's GTD block").
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from numba import njit

from benchmarks import thesis
from horde.core.engine.layout import Step
from horde.core.learners import GTD_CODE, gtd_pass


@njit
def replay(t, b, stream, n_s, repeats):  # type: ignore[no-untyped-def]
    """Block b learns the recorded transitions (features[i] -> features[i + 1]) `repeats` times over."""
    features, values, counts, rho, gamma_tp1 = stream
    lay = t.lay
    db = lay.block_hi[b] - lay.block_lo[b]
    for _ in range(repeats):
        for i in range(features.shape[0] - 1):
            t.cls.rho[:] = rho[i + 1]
            t.cls.gamma_tp1[:] = gamma_tp1[i + 1]
            x_t, x_tp1 = features[i, : counts[i]], features[i + 1, : counts[i + 1]]
            stp = Step(x_t, values[i, : counts[i]], x_tp1, values[i + 1, : counts[i + 1]], 0, 1.0, n_s)
            gtd_pass.prepare(b, lay, t.dem, t.cls, t.onl, t.scr, False)
            gtd_pass.columns(b, db - db, db, lay, t.wts, t.dem, t.cls, stp, t.scr, 0)
            gtd_pass.finish(b, lay, t.wts, t.dem, t.cls, t.onl, stp, t.scr, False)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--demons", type=int, default=100)
    parser.add_argument("--steps", type=int, default=3000, help="transitions recorded from the thesis loop")
    parser.add_argument("--repeats", type=int, default=20, help="replays of the stream in one timing")
    args = parser.parse_args()
    sim = thesis.simulation(args.demons)
    sim.threads = 1
    sim.run(2000)
    t = sim.learner.engine.t
    (blocks,) = np.nonzero(t.lay.learner == GTD_CODE)
    b = int(blocks[0])
    g = int(t.lay.group[b])
    recorded, recorded_values, rho, gamma_tp1 = [], [], [], []
    for _ in range(args.steps):
        sim.run(1)
        recorded.append(t.coded.features[g, : t.coded.counts[g]].copy())
        recorded_values.append(t.coded.values[g, : t.coded.counts[g]].copy())
        rho.append(t.cls.rho.copy())
        gamma_tp1.append(t.cls.gamma_tp1.copy())
    counts = np.array([len(x) for x in recorded], dtype=np.int64)
    features = np.zeros((len(recorded), int(counts.max())), dtype=np.int64)
    values = np.zeros(features.shape)
    for i, (x, v) in enumerate(zip(recorded, recorded_values, strict=True)):
        features[i, : len(x)] = x
        values[i, : len(v)] = v
    stream = (features, values, counts, np.array(rho), np.array(gamma_tp1))
    n_s = int(t.grp.n_s[g])
    replay(t, b, stream, n_s, 1)  # compiles
    best = float("inf")
    for _ in range(5):
        start = time.process_time()
        replay(t, b, stream, n_s, args.repeats)
        best = min(best, (time.process_time() - start) / (args.repeats * (len(recorded) - 1)))
    db = int(t.lay.block_hi[b] - t.lay.block_lo[b])
    print(f"GTD block of {db} demons in {int(t.lay.ncls[b])} classes over {int(t.lay.rows[b])} features: "
          f"{best * 1e6:.3f} CPU us a step (best of 5; support {int(t.wts.nnz[b])} rows at the end)")  # fmt: skip


if __name__ == "__main__":
    main()
