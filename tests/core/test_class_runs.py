"""TD's walk (`td_pass.walk`) against the plain sums, on the engine's own arrays: it pays what each demon owes on every
support row (owed times its class's trace there) and reads the values at x_{t+1} from the paid rows, whether the walk
takes its rows one, two or four at a time (`td_pass.walk_rows`: four rows in a row that are all paid and read go at
once, else two, else one). x_{t+1} is chosen here so that every kind of run occurs: runs of 1 to 9 support rows, a row
of value 0 inside a run (paid, not read), and rows outside the support (read only). After a step every demon holds its
own class's target policy and continuation (`step.given_to_slots`, `step.continuations_to_slots`), in blocks of five
classes (long runs) and of 300 (a class a demon or two: a look-up a demon)."""

from __future__ import annotations

import numpy as np
import pytest
from benchmarks import workloads

from horde.core.engine.layout import Step
from horde.core.learners import td_pass
from horde.core.simulation import Simulation
from horde.spec import RunSpec

RUNS = (1, 2, 3, 4, 5, 6, 7, 8, 9)  # lengths of the runs of support rows in x_{t+1}, a support row apart


def _x_tp1(support: np.ndarray, rows: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """x_{t+1}'s rows (sorted) and values: the runs above, one value 0 inside the run of 8, and three rows that are not
    in the support."""
    chosen: list[int] = []
    at = 0
    for length in RUNS:
        chosen.extend(range(at, at + length))
        at += length + 1
    assert at <= support.shape[0], "the support holds every run"
    picked = support[chosen]
    outside = np.setdiff1d(np.arange(rows), support)[[0, 5, -1]]
    x = np.sort(np.concatenate([picked, outside])).astype(np.int64)
    v = rng.uniform(0.5, 1.5, x.shape[0])
    v[np.searchsorted(x, support[chosen[sum(RUNS[:7]) + 3]])] = 0.0  # inside the run of 8
    return x, v


def nexting_engine(learner: str, dtype: str) -> Simulation:
    """nexting's 300 demons (five trace classes) of `learner` in `dtype`, after 60 steps: traces on a support of some
    500 rows."""
    data = workloads.spec("nexting", 300, learner).model_dump(by_alias=True)
    data["learning"]["dtype"] = dtype
    sim = Simulation(RunSpec.model_validate(data), np.random.default_rng(0))
    sim.with_metrics = False
    sim.run(60)
    return sim


@pytest.mark.timeout(300)
@pytest.mark.parametrize("dtype", ["float64", "float32"])
def test_the_walk_pays_and_reads_runs_of_rows_as_the_plain_sums(dtype: str) -> None:
    t = nexting_engine("td", dtype).learner.engine.t
    lay, wts = t.lay, t.wts
    lo, hi, woff, voff, toff = (int(a[0]) for a in (lay.block_lo, lay.block_hi, lay.woff, lay.voff, lay.toff))
    db, ncls, rows = hi - lo, int(lay.ncls[0]), int(lay.rows[0])
    assert ncls == 5
    support = wts.support[toff : toff + int(wts.nnz[0])].copy()
    rng = np.random.default_rng(1)
    x, v = _x_tp1(support, rows, rng)
    wts.owed[0, lo:hi] = rng.normal(0.0, 0.1, db)

    theta = wts.theta[woff : woff + rows * db].reshape(rows, db)
    trace = wts.trace[voff : voff + rows * ncls].reshape(rows, ncls)
    of_class = np.repeat(np.arange(ncls), lay.class_hi[:ncls] - lay.class_lo[:ncls])
    owed = wts.owed[0, lo:hi].astype(theta.dtype)  # paid in the weights' dtype
    paid = theta.copy()
    paid[support] = theta[support] + owed * trace[support][:, of_class]
    values = v @ paid[x].astype(np.float64)

    td_pass.walk(0, 0, db, lay, wts, Step(x, v, x, v, 0, 0.25, 0), t.scr, False)

    np.testing.assert_array_equal(theta, paid)  # each weight paid once, in the same operations
    np.testing.assert_allclose(t.scr.values[0, :db], values, rtol=1e-12, atol=1e-12)


@pytest.mark.timeout(300)
@pytest.mark.parametrize(("workload", "demons"), [("nexting", 300), ("off_policy", 600)])
def test_each_demon_holds_its_own_class_policy_and_continuation(workload: str, demons: int) -> None:
    spec = workloads.spec(workload, demons, "gtd")
    sim = Simulation(spec, np.random.default_rng(0))
    sim.with_metrics = False
    sim.run(30)
    t, horde = sim.learner.engine.t, sim.horde
    classes = int(t.lay.ncls[0])
    assert classes == (5 if workload == "nexting" else 300)
    for demon in spec.demons:
        slot = horde.demon_slot[horde.index[demon.name]]
        assert t.dem.gamma[slot] == demon.discount, demon.name
        assert t.dem.cumulant[slot] == t.dem.r[slot], demon.name
        if workload == "off_policy":
            np.testing.assert_array_equal(t.dem.pi[slot], demon.policy.probabilities, err_msg=demon.name)
