"""The compiled loop: bulk runs equal single steps, frozen demons stay frozen, state round-trips, divergence."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from horde.core.horde import HordeState
from horde.core.simulation import Simulation
from horde.scenarios import load_scenario, scenario_dir
from horde.spec import RunSpec


def assert_same(a: HordeState, b: HordeState, atol: float = 0.0) -> None:
    """Equal to the last bit, or within `atol` (relative, for large numbers) where the two took their steps in
    calls of different lengths (GTD's correction owed within a call is paid in another order than at a
    call's end: `scale_fast._columns`)."""

    def same(x: np.ndarray, y: np.ndarray, field: str) -> None:
        if atol == 0.0:
            np.testing.assert_array_equal(x, y, err_msg=field)
        else:
            np.testing.assert_allclose(x, y, rtol=atol, atol=atol, err_msg=field)  # rtol: RUPEE's sums reach 1e7

    for field in ("theta", "w", "e", "h", "delta_e"):  # delta_e_scale, rupee_dot below
        for x, y in zip(getattr(a, field), getattr(b, field), strict=True):
            same(x, y, field)
    for field in ("prediction", "pi", "q", "delta", "delta_stats", "diverged", "class_gamma", "class_pi",
                  "delta_e_scale", "rupee_dot"):  # fmt: skip
        same(getattr(a, field), getattr(b, field), field)


def test_bulk_runs_equal_single_steps() -> None:
    spec = load_scenario(scenario_dir() / "experiment3.toml")
    bulk = Simulation(spec, np.random.default_rng(3))
    single = Simulation(spec, np.random.default_rng(3))
    bulk.run(400)
    for _ in range(400):
        single.step()
    assert_same(bulk.horde_state, single.horde_state)
    assert bulk.position == single.position
    assert bulk.total_steps == single.total_steps == 400
    assert bulk.episode == single.episode > 3


def test_test_runs_freeze_all_but_reset_demons() -> None:
    spec = load_scenario(scenario_dir() / "experiment3.toml")
    sim = Simulation(spec, np.random.default_rng(5))
    assert spec.protocol.test is not None
    learning = np.array([d.reset == "episode" for d in spec.demons])
    assert learning.any() and not learning.all()
    sim.run(2000)
    before = {name: sim.horde.weights(sim.horde_state, name) for name in sim.horde.names}
    sim.run_episode(spec.protocol.test.behaviour, learning)
    for name, on in zip(sim.horde.names, learning, strict=True):
        after = sim.horde.weights(sim.horde_state, name)
        if on:
            assert not np.array_equal(after, before[name]), f"{name} learns during the test episode"
        else:
            np.testing.assert_array_equal(after, before[name], err_msg=f"{name} is frozen")


def test_state_round_trips_through_load() -> None:
    spec = load_scenario(scenario_dir() / "classroom-offpolicy.toml")
    sim = Simulation(spec, np.random.default_rng(1))
    sim.run(500)
    saved_state, saved_world = sim.horde_state, sim.world_state
    saved_rng = sim.rng.bit_generator.state
    sim.run(300)
    after = sim.predictions()
    resumed = Simulation(spec, np.random.default_rng(99))
    resumed.world_state = saved_world
    resumed.horde_state = saved_state
    resumed.rng.bit_generator.state = saved_rng
    resumed.run(300)
    assert resumed.predictions() == pytest.approx(after, abs=1e-12)


def diverging_spec() -> RunSpec:
    demons: list[dict[str, Any]] = [
        {"name": "wild", "learner": "td", "policy": "uniform", "cumulant": {"sensor": "x"}, "alpha": 10,
         "discount": 0.99, "lambda": 0.9},
        {"name": "calm", "learner": "td", "policy": "uniform", "cumulant": {"sensor": "bump"}, "discount": 0.9},
        {"name": "reader", "learner": "gtd", "policy": "uniform", "cumulant": {"mul": [{"prediction": "wild"}, 0]},
         "discount": 0.5},
    ]  # fmt: skip
    return RunSpec.model_validate(
        {
            "world": {"width": 500, "height": 500, "step": 100, "start": [0, 0], "max_steps": 50},
            "features": {"kind": "tiles", "tilings": 4, "tiles": 4},
            "behaviour": "uniform",
            "demons": demons,
            "seed": 2,
        }
    )


def test_a_diverging_demon_is_frozen_and_the_others_go_on() -> None:
    sim = Simulation(diverging_spec())
    sim.run(3000)
    state = sim.horde_state
    wild, calm, reader = (sim.horde.index[n] for n in ("wild", "calm", "reader"))
    assert state.diverged[wild] and not state.diverged[calm] and not state.diverged[reader]
    frozen = sim.horde.weights(state, "wild")
    assert not frozen.any(), "the weights of a diverged demon are set to 0"
    assert np.isfinite(state.prediction).all() and np.isfinite(state.delta[[calm, reader]]).all()
    learned = sim.horde.weights(state, "calm")
    sim.run(200)
    later = sim.horde_state
    np.testing.assert_array_equal(sim.horde.weights(later, "wild"), frozen)
    assert not np.array_equal(sim.horde.weights(later, "calm"), learned), "the others go on learning"


# (learner, step size, meta step size): the learners whose `wild` demon diverges here (GTD2, the original GTD and
# Autostep do not); TIDBD twice, with its meta step size at 1 so that its step sizes overflow before it diverges
FROZEN_LEARNERS = [("td", "constant", 0.01), ("gtd", "constant", 0.01), ("tdrc", "constant", 0.01),
                   ("etd", "constant", 0.01), ("true_online_td", "constant", 0.01),
                   ("true_online_gtd", "constant", 0.01), ("gq", "constant", 0.01), ("td", "tidbd", 0.01),
                   ("td", "tidbd", 1.0)]  # fmt: skip


@pytest.mark.parametrize(("learner", "step_size", "meta_step"), FROZEN_LEARNERS)
def test_a_frozen_demon_stays_at_zero(learner: str, step_size: str, meta_step: float) -> None:
    """Once diverged and frozen, a demon's weights stay 0 and its step sizes finite: an infinite step size
    left in place would write NaN into its weights on every later step, frozen rate 0 or not (inf times 0)."""
    target = {"kind": "fixed", "probabilities": [0.7, 0.1, 0.1, 0.1]}
    demons: list[dict[str, Any]] = [
        {"name": "wild", "learner": learner, "step_size": step_size, "policy": target, "cumulant": {"sensor": "x"},
         "alpha": 10, "discount": 0.99, "lambda": 0.9, "meta_step": meta_step},
        {"name": "calm", "learner": learner, "step_size": step_size, "policy": target,
         "cumulant": {"sensor": "bump"}, "discount": 0.9},
    ]  # fmt: skip
    spec = diverging_spec().model_copy(update={"demons": RunSpec.model_validate(
        {"world": {"width": 500, "height": 500}, "demons": demons}).demons})  # fmt: skip
    sim = Simulation(spec)
    wild, calm = (sim.horde.index[n] for n in ("wild", "calm"))
    for _ in range(3000):
        sim.step()
        if sim.horde_state.diverged[wild]:
            break
    assert sim.horde_state.diverged[wild] and not sim.horde_state.diverged[calm]
    sim.run(300)
    state = sim.horde_state
    theta, w, _ = sim.horde.demon_arrays(state, "wild")
    assert not theta.any() and not w.any(), "a frozen demon's weights stay 0"
    assert np.isfinite(sim.step_sizes("wild")).all()
    assert np.isfinite(state.prediction).all() and np.isfinite(state.delta[calm])


@pytest.mark.parametrize("learner", ["gtd", "tdrc", "td", "etd", "true_online_td", "gq"])
def test_when_a_demon_is_frozen_its_block_reads_its_values_from_whole_weights(learner: str) -> None:
    """A demon of GTD or of the learners sharing its kernel owes its whole update to the next step
    (`learners.gtd_pass`), a GQ demon its correction (`learners.gradient`), a TD, emphatic TD or true online TD
    demon its update (`learners.td_pass`). When a demon of its block is frozen, the block's values at s_{t+1} are
    read again from theta, so what the others owe must be paid first: right after the freeze, `calm`'s prediction
    is its weights times its features (GQ's: the target policy's mean of its action values). `wild` diverges near
    step 200, when `calm` owes something."""
    target = {"kind": "fixed", "probabilities": [0.7, 0.1, 0.1, 0.1]}
    demons: list[dict[str, Any]] = [
        {"name": "wild", "learner": learner, "policy": target, "cumulant": {"sensor": "x"}, "alpha": 2,
         "discount": 0.99, "lambda": 0.9},
        {"name": "calm", "learner": learner, "policy": target, "cumulant": {"sensor": "bump"}, "discount": 0.9},
    ]  # fmt: skip
    spec = diverging_spec().model_copy(update={"demons": RunSpec.model_validate(
        {"world": {"width": 500, "height": 500}, "demons": demons}).demons})  # fmt: skip
    sim = Simulation(spec, cut=0.0)
    wild, calm = (sim.horde.index[n] for n in ("wild", "calm"))
    for _ in range(3000):
        sim.step()
        if sim.horde_state.diverged[wild]:
            break
    state = sim.horde_state
    assert state.diverged[wild] and not state.diverged[calm]
    theta, w, _ = sim.horde.demon_arrays(state, "calm")
    has_w = learner not in ("td", "etd", "true_online_td")
    assert not has_w or np.abs(w).max() > 1e-3, "calm has learned a w: its correction is not 0"
    features, probabilities = state.features[0], target["probabilities"]
    n_s = theta.size // len(probabilities) if learner == "gq" else theta.size  # (GQ: a block of rows per action)
    expected = sum(p * theta[a * n_s + features].sum() for a, p in enumerate(probabilities)) if learner == "gq" \
        else theta[features].sum()  # fmt: skip
    assert state.prediction[calm] == pytest.approx(expected, abs=1e-12)


def test_compiled_metrics_equal_the_numpy_form() -> None:
    """RUPEE's h and average of delta e, and UDE's averages, against metrics.update step by step."""
    from horde.core import metrics

    demons: list[dict[str, Any]] = [
        {"name": "a", "learner": "td", "policy": "uniform", "cumulant": {"sensor": "bump"}, "discount": 0.9},
        # a second trace class in the TD block, written between the first's demons (columns go class by class)
        {"name": "a2", "learner": "td", "policy": "uniform", "cumulant": {"sensor": "y"}, "discount": 0.5},
        {"name": "b", "learner": "td", "policy": "uniform", "cumulant": {"sensor": "x"}, "discount": 0.9},
        {"name": "c", "learner": "gtd", "policy": {"kind": "fixed", "probabilities": [0.7, 0.1, 0.1, 0.1]},
         "cumulant": {"sensor": "y"}, "discount": 0.5},
        {"name": "ctl", "policy": "greedy", "cumulant": {"sensor": "bump"}, "discount": 0.8, "lambda": 0.5},
    ]  # fmt: skip
    spec = RunSpec.model_validate(
        {
            "world": {"width": 500, "height": 500, "step": 50, "start": [0, 0], "max_steps": 10_000},
            "features": {"kind": "tiles", "tilings": 4, "tiles": 4},
            "behaviour": "uniform",
            "demons": demons,
        }
    )  # no episode ends: a step's traces are what its metrics saw
    sim = Simulation(spec, np.random.default_rng(4), cut=0.0)
    horde = sim.horde
    state = sim.horde_state
    blocks = [metrics.BlockMetrics(np.zeros_like(t), np.zeros_like(t), 0.0, np.zeros((t.shape[1], 3)), 0.0)
              for t in state.theta]  # fmt: skip
    for _ in range(300):
        before = sim.horde_state
        result = sim.step()
        after = sim.horde_state
        for b, block in enumerate(horde.blocks):
            group = horde.groups[int(horde.block_group[b])]
            slots = np.arange(horde.block_lo[b], horde.block_lo[b] + block.size)
            demons = horde.slot_demon[slots]
            columns = horde.slot_class[slots] - horde.slot_class[slots[0]]
            x_t = before.features[int(horde.block_group[b])]
            if block.learner == "gq":
                x_t = x_t + result.action * group.coder.n
            e = after.e[b][:, columns]  # each demon's trace
            blocks[b] = metrics.update(blocks[b], after.delta[demons], e, x_t, group.coder.k)
    state = sim.horde_state
    assert np.abs(state.delta).max() > 0
    assert max(block.num_classes for block in horde.blocks) == 2
    for b, block in enumerate(horde.blocks):
        slots = np.arange(horde.block_lo[b], horde.block_lo[b] + block.size)
        np.testing.assert_allclose(state.h[b], blocks[b].h, rtol=0, atol=1e-9)
        scale = state.delta_e_scale[horde.block_group[b]]  # the engine keeps the average divided by it
        np.testing.assert_allclose(state.delta_e[b] * scale, blocks[b].delta_e, rtol=1e-9, atol=1e-12)
        dot = np.einsum("nd,nd->d", state.h[b], state.delta_e[b])
        np.testing.assert_allclose(state.rupee_dot[horde.slot_demon[slots]], dot, rtol=1e-9, atol=1e-15)
        np.testing.assert_allclose(state.delta_stats[horde.slot_demon[slots]], blocks[b].delta_stats, atol=1e-12)
    assert horde.rupee(state).max() > 0 and np.isfinite(horde.ude(state)).all()


def test_the_readout_equals_the_state() -> None:
    """Simulation.readout (O(D), RUPEE's dot products kept up to date) against the full state."""
    spec = load_scenario(scenario_dir() / "experiment3.toml")
    sim = Simulation(spec, np.random.default_rng(2))
    sim.run(3000)  # several episodes, and past the first steps whose averages fold their scale
    out, state = sim.readout(), sim.horde_state
    np.testing.assert_allclose(out.rupee, sim.horde.rupee(state), rtol=1e-9, atol=1e-12)
    np.testing.assert_array_equal(out.ude, sim.horde.ude(state))
    for field in ("prediction", "cumulant", "delta", "diverged"):
        np.testing.assert_array_equal(getattr(out, field), getattr(state, field))
    assert out.rupee.max() > 0
    resumed = Simulation(spec, np.random.default_rng(9))
    resumed.world_state = sim.world_state
    resumed.horde_state = state
    np.testing.assert_allclose(resumed.readout().rupee, out.rupee, rtol=1e-12)


def test_a_changed_set_of_demons_keeps_the_others_and_codes_the_sensors_where_the_agent_stands() -> None:
    spec = load_scenario(scenario_dir() / "nexting.toml")
    data = spec.model_dump(by_alias=True)
    data["demons"] = data["demons"][:40]
    small = RunSpec.model_validate(data)
    sim = Simulation(small, np.random.default_rng(1))
    sim.run(120)
    before = {name: sim.horde.weights(sim.horde_state, name) for name in sim.horde.names[:30]}
    data["demons"] = data["demons"][:30]
    fewer = sim.with_spec(RunSpec.model_validate(data))
    for name, theta in before.items():
        np.testing.assert_array_equal(fewer.horde.weights(fewer.horde_state, name), theta)
    features = fewer.horde_state.features[0]
    sensors = sim.sensors[None, :]  # read where the agent stands, before the change
    expected = fewer.horde.groups[0].coder.active(np.zeros(1), np.zeros(1), sensors=sensors)[0]
    np.testing.assert_array_equal(features, expected)
    # The kept demons go on from where the agent stands as they would have among all 40 (traces restarted
    # in both, the same draws).
    draws = sim.rng.bit_generator.state
    fewer.run(20)
    sim.rng.bit_generator.state = draws
    sim.learner.observe(sim.sensors)
    sim.run(20)
    assert fewer.position == sim.position and fewer.total_steps == sim.total_steps
    for name in before:
        after = fewer.horde.weights(fewer.horde_state, name)
        np.testing.assert_array_equal(after, sim.horde.weights(sim.horde_state, name), err_msg=name)
    assert any(np.abs(fewer.horde.weights(fewer.horde_state, n) - t).max() > 0 for n, t in before.items())


def test_forward_of_some_demons_equals_forward_of_all() -> None:
    spec = load_scenario(scenario_dir() / "experiment3.toml")
    sim = Simulation(spec, np.random.default_rng(3))
    sim.run(1500)
    state = sim.horde_state
    x, y = np.array([50.0, 250.0, 420.0]), np.array([30.0, 260.0, 410.0])
    full = sim.horde.forward(state, x, y)
    for name in sim.horde.names:
        i = sim.horde.index[name]
        some = sim.horde.forward(state, x, y, demons=[name])
        np.testing.assert_array_equal(some.prediction[:, i], full.prediction[:, i])
        np.testing.assert_array_equal(some.pi[:, i], full.pi[:, i])
        np.testing.assert_array_equal(some.q[:, i], full.q[:, i])
    needed = {name: set(np.flatnonzero(sim.horde.needs([name])).tolist()) for name in sim.horde.names}
    assert all(sim.horde.index[name] in demons for name, demons in needed.items())
    assert sim.horde.num_demons > 1 and min(map(len, needed.values())) == 1, "a demon reading none needs only itself"
