"""GymSimulation, the Gymnasium source a live run steps: its state goes out and comes back exactly."""

from __future__ import annotations

import numpy as np
import pytest
from tests.server.test_gym_runs import gym_spec

from horde.spec import RunSpec
from horde.worlds.gym_simulation import GymSimulation, GymStateError, _rng_state, _rng_words


def test_the_environment_generator_survives_its_32_bit_words() -> None:
    rng = np.random.default_rng(2**70 + 12345)
    rng.random(3)
    state = rng.bit_generator.state
    assert _rng_state(_rng_words(state)) == state


def test_a_world_state_put_back_replays_the_same_steps() -> None:
    sim = GymSimulation(RunSpec.model_validate(gym_spec()), np.random.default_rng(1))
    sim.run(150)
    saved, rng = sim.world_state, sim.rng.bit_generator.state
    sim.run(300)  # crosses the 200-step time limit: an episode ends and the environment resets itself
    after = (sim.sensors, sim.world_state.steps.copy())
    sim.world_state = saved
    sim.rng.bit_generator.state = rng
    sim.run(300)
    np.testing.assert_array_equal(sim.sensors, after[0])
    np.testing.assert_array_equal(sim.world_state.steps, after[1])


def test_an_environment_without_a_state_runs_but_cannot_be_restored() -> None:
    sim = GymSimulation(RunSpec.model_validate(gym_spec()), np.random.default_rng(1))
    sim.agent.world.env.unwrapped.state = None  # as an environment that keeps its state elsewhere
    saved = sim.world_state  # a view of the run still works
    assert saved.env_state.shape == (0,)
    with pytest.raises(GymStateError, match="keeps no state"):
        sim.world_state = saved
