"""The one engine runs true online TD/GTD(lambda), emphatic TD(lambda), TIDBD and Autostep as the oracle does.

Every transition of the simulation is replayed into `reference.ReferenceHorde`; after every step every
demon's weights, trace and prediction agree to 1e-9 (relative, for numbers above 1) with the trace cut at
0, and to 1e-5 with the default cut. Demons that may share a trace do (same target policy, continuation
and, for the dutch traces, alpha); the adaptive demons' per-weight step sizes are compared too.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from grids import CRIT, GOAL, PIT, WALL, grid
from horde.core.engine.blocks import TRACE_CUT
from horde.core.engine.layout import Step
from horde.core.learners.adaptive import (
    EXP_ANY,
    EXP_SMALL,
    EXP_TINY,
    SCALE_FLOOR,
    SMALL_EXP,
    TINY_EXP,
    exp_kind,
    exp_small,
    exp_tiny,
)
from horde.core.learners.online import differs_less, values_at_next
from horde.core.reference import ReferenceHorde
from horde.core.simulation import Simulation
from horde.spec import RunSpec, learner_info

FIXED = {"kind": "fixed", "probabilities": [0.4, 0.1, 0.1, 0.4]}
DEMONS: list[dict[str, Any]] = [
    {"name": "base", "policy": {"kind": "softmax", "temperature": 0.5}, "cumulant": {"sensor": "reward"}},
    {"name": "to_goal", "learner": "true_online_td", "policy": {"of": "base"}, "outcome": {"sensor": "in:goal"},
     "discount": 0.9},
    {"name": "to_goal_b", "learner": "true_online_td", "policy": {"of": "base"}, "cumulant": {"sensor": "bump"},
     "discount": 0.9},
    {"name": "to_goal_a", "learner": "true_online_td", "policy": {"of": "base"}, "cumulant": 0.1, "alpha": 0.05},
    {"name": "steps_to", "learner": "true_online_td", "policy": FIXED, "cumulant": 1, "discount": 0.9,
     "lambda": 0.5},
    {"name": "gtd_to", "learner": "true_online_gtd", "policy": FIXED, "cumulant": {"sensor": "bump"},
     "discount": 0.8, "alpha_w": 0.05},
    {"name": "gtd_to_b", "learner": "true_online_gtd", "policy": {"of": "base"}, "outcome": {"sensor": "in:goal"}},
    {"name": "emph", "learner": "etd", "policy": FIXED, "cumulant": {"sensor": "reward"}, "discount": 0.9},
    {"name": "emph_b", "learner": "etd", "policy": FIXED, "cumulant": 0.2, "discount": 0.9, "alpha": 0.02},
    {"name": "emph_c", "learner": "etd", "policy": "uniform", "outcome": {"sensor": "in:crit"},
     "continuation": {"if": {"sensor": "in:crit"}, "then": 0, "else": 1}},
    {"name": "tidbd", "learner": "td", "step_size": "tidbd", "meta_step": 0.05, "policy": FIXED,
     "cumulant": {"sensor": "bump"}, "discount": 0.8},
    {"name": "tidbd_b", "learner": "td", "step_size": "tidbd", "policy": FIXED, "cumulant": 1, "discount": 0.8},
    {"name": "auto", "learner": "td", "step_size": "autostep", "policy": {"of": "base"},
     "outcome": {"sensor": "in:goal"}, "alpha": 0.5},
    {"name": "auto_b", "learner": "td", "step_size": "autostep", "meta_step": 0.1, "policy": "uniform",
     "cumulant": 1, "discount": 0.95, "reset": "never"},
    {"name": "auto_reset", "learner": "td", "step_size": "autostep", "policy": "uniform", "cumulant": 1,
     "discount": 0.9, "reset": "episode", "meta_step": 0.2},
    {"name": "plain_td", "learner": "td", "policy": FIXED, "cumulant": 1, "discount": 0.8},
]  # fmt: skip


def spec(behaviour: Any = "uniform") -> RunSpec:
    return RunSpec.model_validate(
        {
            "world": grid(GOAL, PIT, WALL, CRIT, slip=0.1, max_steps=40),
            "features": {"kind": "stripes", "parts": 5},
            "learning": {"lambda": 0.9, "alpha": 0.1, "alpha_w": 0.01, "meta_step": 0.02, "autostep_tau": 100},
            "behaviour": behaviour,
            "demons": DEMONS,
            "seed": 11,
        }
    )


def compare(sim: Simulation, ref: ReferenceHorde, step: int, tolerance: float) -> float:
    state = sim.horde_state
    largest = 0.0
    for i, name in enumerate(sim.horde.names):
        demon = ref.demons[name]
        theta, w, e = sim.horde.demon_arrays(state, name)
        pairs = [("theta", theta, demon.theta), ("e", e, demon.e),
                 ("prediction", state.prediction[i : i + 1], np.array([demon.prediction]))]  # fmt: skip
        if learner_info(demon.spec.learner).secondary:  # gq, gtd, true online gtd, tdrc (its h)
            pairs.append(("w", w, demon.w))
        if demon.mode != "constant":
            pairs.append(("h", w, demon.h))
            pairs.append(("alphas", sim.step_sizes(name), demon.alphas))
        for what, ours, plain in pairs:
            gap = float(np.abs(ours - plain).max()) / max(1.0, float(np.abs(plain).max()))  # relative above 1
            largest = max(largest, gap)
            assert gap <= tolerance, f"{what} of {name!r} at step {step}: gap {gap:.3g}"
    return largest


def replay(run: RunSpec, cut: float, steps: int, watch: Any = None) -> tuple[Simulation, ReferenceHorde, int]:
    """The engine's own transitions replayed into ReferenceHorde, compared at every step (1e-9 with the cut
    at 0, 1e-5 with the default cut); returns the simulation, the oracle and the number of episodes. `watch`,
    if given, is called with the simulation before each step and returns what to call with the step's result
    after it."""
    sim = Simulation(run, cut=cut)
    ref = ReferenceHorde(run)
    names = sim.world.sensor_names
    ref.observe(*sim.position, dict(zip(names, sim.start_sensors.tolist(), strict=True)))
    tolerance = 1e-9 if cut == 0.0 else 1e-5
    episodes = 0
    for step in range(1, steps + 1):
        after = watch(sim) if watch is not None else None
        result = sim.step()
        sensors = sim.sensors
        ref.learn(result.action, sim.behaviour_probability, float(sensors[0]), float(sensors[1]),
                  dict(zip(names, sensors.tolist(), strict=True)), result.terminated)  # fmt: skip
        if result.done:
            episodes += 1
            ref.observe(*sim.position, dict(zip(names, sim.start_sensors.tolist(), strict=True)))
        compare(sim, ref, step, tolerance)
        if after is not None:
            after(result)
    return sim, ref, episodes


@pytest.mark.slow
@pytest.mark.parametrize("cut", [0.0, TRACE_CUT], ids=["cut=0", "default cut"])
@pytest.mark.parametrize("behaviour", ["uniform", {"kind": "epsilon_greedy", "demon": "base", "epsilon": 0.5}])
def test_engine_equals_reference_at_every_step(behaviour: Any, cut: float) -> None:
    sim, ref, episodes = replay(spec(behaviour), cut, 800)
    assert episodes >= 10
    horde = sim.horde
    slot_class = {n: horde.slot_class[horde.demon_slot[horde.index[n]]] for n in horde.names}
    assert slot_class["to_goal"] == slot_class["to_goal_b"], "true online demons with one alpha share a trace"
    assert slot_class["to_goal"] != slot_class["to_goal_a"], "a dutch trace holds alpha: no sharing across alphas"
    assert slot_class["emph"] == slot_class["emph_b"], "emphatic demons of one policy and continuation share"
    assert slot_class["tidbd"] == slot_class["tidbd_b"]
    moved = {n: float(np.abs(sim.step_sizes(n) - ref.demons[n].alpha).max())
             for n in ("tidbd", "auto", "auto_b", "auto_reset")}  # fmt: skip
    assert min(moved.values()) > 1e-6, moved  # the step sizes did adapt
    assert not sim.horde_state.diverged.any()


@pytest.mark.parametrize("cut", [0.0, TRACE_CUT], ids=["cut=0", "default cut"])
def test_true_online_gtds_w_trace_outlives_the_dutch_trace_that_rho_cut(cut: float) -> None:
    """True online GTD's w trace decays by rho_{t-1}, its other two traces by rho_t. A target policy that never
    takes three of the four actions cuts e and e_grad to zero at every such step (rho_t = 0), while e_w lives on
    one step more, and w moves along it: e_grad and e_w keep their own support (`Online.support2`). The demon is
    alone in its block, so no other class's trace keeps those rows. Equal to the reference at every step, and the
    two traces are zero off their support."""
    data = spec().model_dump(by_alias=True)
    data["demons"] = [data["demons"][0], {
        "name": "one_way", "learner": "true_online_gtd", "policy": {"kind": "fixed", "probabilities": [1, 0, 0, 0]},
        "cumulant": {"sensor": "bump"}, "discount": 0.9, "alpha_w": 0.05,
    }]  # fmt: skip
    sim, ref, episodes = replay(RunSpec.model_validate(data), cut, 400)
    assert episodes >= 3
    engine = sim.learner.engine
    (b,) = [b for b, block in enumerate(engine.horde.blocks) if block.kernel.learner == "true_online_gtd"]
    at, kept = int(engine.t.lay.toff[b]), int(engine.t.onl.nnz2[b])
    support = engine.t.onl.support2[at : at + kept]
    assert kept > 0 and (np.diff(support) > 0).all()
    assert set(np.flatnonzero((engine.traces2(b) != 0.0).any(axis=(0, 2)))) <= set(support.tolist())
    assert float(np.abs(ref.demons["one_way"].w).max()) > 1e-6, "w moved"


@pytest.mark.slow
@pytest.mark.parametrize(("meta_step", "kind"), [(0.01, EXP_TINY), (0.05, EXP_SMALL), (0.2, EXP_ANY)])
def test_autostep_equals_the_reference_with_each_kind_of_exp(meta_step: float, kind: int) -> None:
    """A block of Autostep demons whose meta step sizes are at most 0.01, 1/16 or above: its meta steps take
    `_exp_tiny`, `_exp_small` or math.exp, and each equals the oracle (np.exp) to 1e-9 with the cut at 0."""
    assert exp_kind(meta_step) == kind
    data = spec().model_dump(by_alias=True)
    auto = [d["name"] for d in data["demons"] if d["step_size"] == "autostep"]
    data["demons"] = [{**d, "meta_step": meta_step} if d["name"] in auto else d
                      for d in data["demons"] if d["name"] in [*auto, "base"]]  # fmt: skip
    sim, ref, episodes = replay(RunSpec.model_validate(data), 0.0, 300)
    assert len(auto) == 3 and episodes >= 3
    moved = [float(np.abs(sim.step_sizes(n) - ref.demons[n].alpha).max()) for n in auto]
    assert min(moved) > 1e-6, moved  # the step sizes did adapt


def _gtd_demons() -> RunSpec:
    """Three true online GTD demons: off-policy under a fixed policy (rho 0.4 and 1.6) and the base demon's softmax,
    and on-policy."""
    data = spec().model_dump(by_alias=True)
    data["demons"] = [d for d in data["demons"] if d["name"] in ("base", "gtd_to", "gtd_to_b")]
    data["demons"].append({"name": "gtd_on", "learner": "true_online_gtd", "policy": "uniform", "cumulant": 1,
                           "discount": 0.95, "alpha_w": 0.05})  # fmt: skip
    return RunSpec.model_validate(data)


def _gtd_blocks(sim: Simulation) -> list[int]:
    return [b for b, block in enumerate(sim.learner.engine.horde.blocks) if block.kernel.learner == "true_online_gtd"]


def test_true_online_gtds_w_pass_reads_what_the_next_step_needs_less_what_the_cut_takes() -> None:
    """True online GTD reads w once a step (`true_online._togtd_weights`): the pass that moves w also reads, from
    the moved rows, w . e_grad_t and w . x_{t+1} (`Online.w_read`); the next step takes w . e_grad_{t+1} = rho
    (gamma lambda w . e_grad_t + w . x_{t+1}) less w times each entry that the trace cut took (w_read[2]). With a
    cut high enough to take entries often: after every step what the pass read equals those sums over the
    engine's arrays, and the w . e_grad the step took equals the sum over its e_grad; at many steps the recursion
    alone (without the cut's entries) would have missed it."""
    sim = Simulation(_gtd_demons(), cut=2e-3)
    engine = sim.learner.engine
    t, lam = engine.t, 0.9
    checked = cut_steps = 0
    for _ in range(400):
        before = {b: (engine.weights(t.wts.w, b).astype(float), t.onl.w_read[:2].copy(), t.cls.gamma.copy(),
                      int(t.onl.w_read_ok[b])) for b in _gtd_blocks(sim)}  # fmt: skip
        if sim.step().done:
            continue
        x = t.coded.features[0, : t.coded.counts[0]]
        v = t.coded.values[0, : t.coded.counts[0]]
        for b, (w_before, read, gamma, ok) in before.items():
            lo, db, coff = int(t.lay.block_lo[b]), int(t.lay.block_hi[b] - t.lay.block_lo[b]), int(t.lay.coff[b])
            cls = t.lay.slot_class[lo : lo + db]
            e_grad = engine.traces2(b)[0].astype(float)  # [rows, classes of the block]: e_grad_{t+1}
            w = engine.weights(t.wts.w, b).astype(float)
            np.testing.assert_allclose(t.onl.w_read[0, lo : lo + db], (w * e_grad[:, cls - coff]).sum(axis=0),
                                       rtol=1e-12, atol=1e-14)  # fmt: skip
            np.testing.assert_allclose(t.onl.w_read[1, lo : lo + db], v @ w[x], rtol=1e-12, atol=1e-14)
            direct = (w_before * e_grad[:, cls - coff]).sum(axis=0)
            np.testing.assert_allclose(t.onl.w_read[2, lo : lo + db], direct, rtol=1e-11, atol=1e-13)
            if not ok:  # the step read w afresh (the first of a run or of an episode): no recursion to check
                continue
            rho = t.cls.rho[cls]
            by_recursion = rho * gamma[cls] * lam * read[0, lo : lo + db] + rho * read[1, lo : lo + db]
            checked += 1
            cut_steps += not np.allclose(by_recursion, direct, rtol=1e-11, atol=1e-13)
    assert checked > 600 and cut_steps > 20, (checked, cut_steps)


def _bold_tidbd() -> RunSpec:
    """TIDBD demons, some bold (meta step sizes 0.2 and 0.4; one keeps its weights across episodes), whose meta steps'
    arguments |mu delta phi h| go beyond 1/16, where the walk's polynomial exp stops (`adaptive.large_meta_steps`),
    and which stay finite for 300 steps (a meta step size of 0.3 or a cumulant of 2 diverges here)."""
    data = spec().model_dump(by_alias=True)
    bold = {"learner": "td", "step_size": "tidbd", "meta_step": 0.2, "policy": FIXED, "cumulant": 1, "discount": 0.9}
    data["demons"] = [d for d in data["demons"] if d["name"] in ("base", "tidbd", "tidbd_b")] + [
        {**bold, "name": "bold"},
        {**bold, "name": "bold_kept", "reset": "never", "discount": 0.8},
        {**bold, "name": "bold_b", "cumulant": -1, "discount": 0.5, "meta_step": 0.4},
    ]
    return RunSpec.model_validate(data)


def _tidbd_blocks(sim: Simulation) -> list[int]:
    return [b for b, block in enumerate(sim.learner.engine.horde.blocks) if block.step_size == "tidbd"]


def test_tidbd_takes_its_larger_meta_steps_apart_and_equals_the_reference() -> None:
    """TIDBD's walk takes exp as a polynomial good to 1/16; a demon whose largest |phi h| over x_t's rows, times
    |mu delta|, may reach beyond takes its meta steps apart with the full exp (`adaptive.large_meta_steps`). The
    largest |phi h| comes from the last step's walk, which reads it over x_tp1's rows after they moved
    (`Online.w_read[0]`), or is read afresh where that does not hold: the first step, an episode's start. After
    every step it equals the largest |phi h| over the new state's rows; the engine equals the oracle to 1e-9 over
    steps where some demons went each way, across episodes."""
    counts = {"apart": 0, "walked": 0}

    def watch(sim: Simulation) -> Any:
        engine = sim.learner.engine
        t = engine.t
        (b,) = _tidbd_blocks(sim)
        lo, db = int(t.lay.block_lo[b]), int(t.lay.block_hi[b] - t.lay.block_lo[b])
        meta, largest, ok = t.onl.meta[lo : lo + db], t.onl.w_read[0, lo : lo + db].copy(), int(t.onl.w_read_ok[b])

        def after(result: Any) -> None:
            delta = t.dem.delta[lo : lo + db]
            if ok:
                beyond = np.abs(meta * delta) * largest > SMALL_EXP
                counts["apart"] += int(beyond.sum())
                counts["walked"] += int((~beyond & (delta != 0.0)).sum())
            if result.done:
                assert t.onl.w_read_ok[b] == 0, "a new episode's first step reads the largest |phi h| afresh"
                return
            x = t.coded.features[0, : t.coded.counts[0]]
            v = t.coded.values[0, : t.coded.counts[0]]
            h = engine.weights(t.wts.w, b)
            np.testing.assert_array_equal(t.onl.w_read[0, lo : lo + db], np.abs(v[:, None] * h[x]).max(axis=0))

        return after

    sim, _, episodes = replay(_bold_tidbd(), 0.0, 300, watch)
    apart, walked = counts["apart"], counts["walked"]
    assert not sim.horde_state.diverged.any()
    assert episodes >= 3 and apart > 50 and walked > 500, (episodes, apart, walked)


def test_tidbds_meta_steps_beyond_the_polynomials_reach_take_the_full_exp() -> None:
    """The oracle's comparison above cannot tell the walk's polynomial from exp below arguments of about 0.7 (its
    remainder there is under 1e-9): here h is loaded large (+-10 for the bold demons, 40 and -60 for the two gentle
    ones, whose h was too small for any argument beyond 1/16 before: arguments of several units), and at each of
    three steps every step size of x_t's rows is alpha exp(mu delta phi h), from the step's own TD error, the h and
    alpha before it, to 1e-13 (a degree-9 polynomial is 2e-12 off at 0.3, 1e-4 at 2). The first step counts the
    largest |phi h| afresh (a load: what the last walk read is of the h before it), the next two take what the
    walk read."""
    sim = Simulation(_bold_tidbd(), cut=0.0)
    sim.run(20)
    engine, state = sim.learner.engine, sim.horde_state
    loaded = {"tidbd": 40.0, "tidbd_b": -60.0, "bold": 10.0, "bold_b": -10.0}
    for name, value in loaded.items():
        sim.horde.demon_arrays(state, name)[1][:] = value
    sim.horde_state = state
    t = engine.t
    largest_argument = 0.0
    for step in range(3):
        x = t.coded.features[0, : t.coded.counts[0]].copy()
        v = t.coded.values[0, : t.coded.counts[0]].copy()
        before = {n: (sim.step_sizes(n), sim.horde.demon_arrays(sim.horde_state, n)[1].copy())
                  for n in ("tidbd", "bold", "bold_kept", "bold_b")}  # fmt: skip
        assert not sim.step().done
        for name, (alphas, h) in before.items():
            slot = int(sim.horde.demon_slot[sim.horde.index[name]])
            argument = t.onl.meta[slot] * t.dem.delta[slot] * v * h[x]
            largest_argument = max(largest_argument, float(np.abs(argument).max()))
            if step == 0 and name in ("tidbd", "tidbd_b"):
                assert np.abs(argument).max() > 0.3, (name, argument)  # (the polynomial is off by over 1e-13)
            expected = alphas.copy()
            expected[x] = alphas[x] * np.exp(argument)
            np.testing.assert_allclose(sim.step_sizes(name), expected, rtol=1e-13, atol=0, err_msg=name)
    assert largest_argument > 1.0, largest_argument
    assert not sim.horde_state.diverged.any()


@pytest.mark.parametrize("load", ["horde_state", "learner_state"])
@pytest.mark.parametrize("learner", ["true_online_gtd", "tidbd"])
def test_a_state_loaded_into_a_running_engine_is_read_afresh(learner: str, load: str) -> None:
    """A running engine whose weights (`horde_state`) or traces and step sizes (`learner_state`) are put back from
    50 steps before goes on as a new engine given the same state does, to the last bit: what its last walk read
    for the next step (true online GTD's w . e_grad and w . x; TIDBD's largest |phi h|, which chooses each demon's
    exp, after a horde state: a learner state leaves h as it was) no longer holds, and the next step reads it
    afresh."""
    run = _gtd_demons() if learner == "true_online_gtd" else _bold_tidbd()
    blocks = _gtd_blocks if learner == "true_online_gtd" else _tidbd_blocks
    sim = Simulation(run, cut=0.0)
    sim.run(150)
    earlier = sim.horde_state if load == "horde_state" else sim.learner_state()
    sim.run(50)
    fresh = Simulation(run, cut=0.0)
    fresh.horde_state = sim.horde_state
    fresh.load_learner_state(sim.learner_state())
    if load == "horde_state":
        sim.horde_state = fresh.horde_state = earlier
    else:
        sim.load_learner_state(earlier)
        fresh.load_learner_state(earlier)
    fresh.world_state = sim.world_state
    fresh.rng.bit_generator.state = sim.rng.bit_generator.state
    sim.run(100)
    fresh.run(100)
    ours, theirs = sim.learner.engine, fresh.learner.engine
    for b in blocks(sim):
        for flat in ("theta", "w"):
            np.testing.assert_array_equal(theirs.weights(getattr(theirs.t.wts, flat), b),
                                          ours.weights(getattr(ours.t.wts, flat), b))  # fmt: skip
    np.testing.assert_array_equal(fresh.readout().prediction, sim.readout().prediction)


def _sparse(pairs: dict[int, float]) -> tuple[np.ndarray, np.ndarray]:
    rows = sorted(pairs)
    return np.array(rows, dtype=np.int64), np.array([pairs[r] for r in rows])


@pytest.mark.parametrize(
    ("x_t", "x_tp1", "fewer"),
    [
        ({1: 1.0, 4: 1.0, 7: 1.0}, {1: 1.0, 4: 1.0, 7: 1.0}, True),  # none differ
        ({1: 1.0, 4: 1.0, 7: 1.0}, {1: 1.0, 5: 1.0, 7: 1.0}, True),  # 4 left, 5 came: 2 of 3
        ({1: 1.0, 4: 1.0, 7: 1.0}, {1: 1.0, 4: 0.5, 8: 1.0}, False),  # 4's value, 7 left, 8 came: 3 of 3
        ({1: 1.0, 4: 1.0}, {2: 1.0, 5: 1.0, 9: 1.0}, False),  # all five differ
        ({}, {3: 1.0}, False),  # nothing to start from: the sum over x_tp1
    ],
)
def test_which_rows_differ_between_two_states(x_t: dict[int, float], x_tp1: dict[int, float], fewer: bool) -> None:
    """`differs_less`: a row counts where it is in one state only or its value changed there."""
    assert differs_less(*_sparse(x_t), *_sparse(x_tp1)) == fewer


@pytest.mark.parametrize("dtype", ["float64", "float32"])
def test_the_values_at_the_next_state_from_the_last_values_and_the_rows_that_differ(dtype: str) -> None:
    """`online.values_at_next` (TIDBD's, Autostep's and true online GTD's values before the step): theta . x_tp1 from
    each demon's stored value at x_t and the rows where x_tp1 differs (one row left, one came, one value changed),
    or summed over x_tp1 where most rows differ; equal to the sum over x_tp1 either way. A value at x_t that is
    not theta . x_t shows in the first case only: that is the branch taken."""
    data = spec().model_dump(by_alias=True)
    data["learning"]["dtype"] = dtype
    sim = Simulation(RunSpec.model_validate(data), cut=0.0)
    engine = sim.learner.engine
    t = engine.t
    b, _ = engine.horde.locate("tidbd")
    lo, theta = int(t.lay.block_lo[b]), engine.weights(t.wts.theta, b)
    db = theta.shape[1]
    theta[:] = np.random.default_rng(3).normal(size=theta.shape)
    x_t, v_t = _sparse({2: 1.0, 5: 0.5, 9: 1.0, 11: 1.0, 14: 2.0})
    near = _sparse({2: 1.0, 5: 0.25, 11: 1.0, 13: 1.0, 14: 2.0})  # 9 left, 13 came, 5's value changed
    far = _sparse({0: 1.0, 3: 1.0, 6: 1.0})
    for (x_tp1, v_tp1), from_x_t in ((near, True), (far, False)):
        exact = theta[x_tp1].astype(float).T @ v_tp1
        stale = 1.0  # each demon's stored value at x_t, off by this
        t.dem.q[lo : lo + db, 0] = theta[x_t].astype(float).T @ v_t + stale
        acc = np.zeros(db)
        values_at_next(b, 0, db, t.lay, t.wts, t.dem, Step(x_t, v_t, x_tp1, v_tp1, 0, 0.25, 0), acc)
        np.testing.assert_allclose(acc, exact + (stale if from_x_t else 0.0), rtol=0, atol=1e-12)


@pytest.mark.parametrize(("exp", "bound"), [(exp_tiny, TINY_EXP), (exp_small, SMALL_EXP)])
def test_the_polynomial_exps_of_the_autostep_kernel_are_exp_to_rounding(exp: Any, bound: float) -> None:
    """Autostep's meta step evaluates exp on [-mu, mu] as a polynomial when mu <= 1/16 (learners/adaptive.py)."""
    xs = np.linspace(-bound, bound, 20001)
    relative = np.array([abs(exp(x) - np.exp(x)) for x in xs]) / np.exp(xs)
    assert relative.max() < 5e-16


def test_autostep_keeps_each_demons_largest_step_size() -> None:
    """`Online.step_max`, which Autostep's one walk trusts as an upper bound of a demon's stored step sizes (no step
    size is read to decide that M stays 1: learners/adaptive.py): after every step it is the largest step size the
    demon has stored since it last restarted (its meta steps move some up and some down; a demon that forgets its
    weights restarts them at alpha at an episode's end), and it is counted again when step sizes are loaded (and
    when a demon's scale is folded into its step sizes, below 1e-150: not reached here)."""
    sim = Simulation(spec(), cut=0.0)
    engine = sim.learner.engine
    onl = engine.t.onl
    demons = {}
    for name in ("auto", "auto_b", "auto_reset"):
        b, col = engine.horde.locate(name)
        demons[name] = (b, col, int(engine.horde.demon_slot[engine.horde.index[name]]))
    seen = {name: float(engine.weights(onl.step_a, b)[:, col].max()) for name, (b, col, _) in demons.items()}
    restarts = 0
    for step in range(300):
        result = sim.step()
        for name, (b, col, slot) in demons.items():
            stored = engine.weights(onl.step_a, b)[:, col]
            restart = result.done and name == "auto_reset"
            seen[name] = float(stored.max()) if restart else max(seen[name], float(stored.max()))
            assert onl.step_max[slot] == seen[name], f"{name} at step {step}"
        restarts += result.done
    assert restarts >= 3
    now = {name: float(engine.weights(onl.step_a, b)[:, col].max()) for name, (b, col, _) in demons.items()}
    assert any(now[name] < seen[name] for name in demons), "some demon's largest step size went down since"
    onl.step_max[:] = 0.0
    engine.load_adaptive_state(engine.adaptive_state())
    for name, (_, _, slot) in demons.items():
        assert onl.step_max[slot] == now[name]


@pytest.mark.parametrize("dtype", ["float64", "float32"])
def test_a_folded_scale_counts_the_largest_step_size_again(dtype: str) -> None:
    """A demon's step-size scale below SCALE_FLOOR is folded into its stored step sizes; their largest is then
    counted from the stored products (in float32 a product may round above the float64 one)."""
    data = spec().model_dump(by_alias=True)
    data["learning"]["dtype"] = dtype
    sim = Simulation(RunSpec.model_validate(data), cut=0.0)
    sim.run(30)
    engine = sim.learner.engine
    onl = engine.t.onl
    b, col = engine.horde.locate("auto")
    slot = int(engine.horde.demon_slot[engine.horde.index["auto"]])
    onl.scale[slot] = SCALE_FLOOR / 3
    onl.step_max[slot] = np.inf  # not known: the two passes, which fold
    sim.step()
    assert onl.scale[slot] == 1.0, "the scale was folded"
    stored = engine.weights(onl.step_a, b)[:, col]
    assert onl.step_max[slot] == stored.max()
