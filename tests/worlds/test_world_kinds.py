"""The world kinds beyond the grid: spec validation, the environment contract, policies over N actions."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from pydantic import ValidationError

from horde.core.check import WorldCheckError
from horde.core.horde import Horde
from horde.core.learner import Learner
from horde.core.policies import sign_policy
from horde.spec import RunSpec
from horde.worlds.check import check_world
from horde.worlds.gym_spaces import resolve_world
from horde.worlds.gymnasium import GymAgent, GymWorld


def tiled(*sensors: tuple[str, float, float]) -> dict[str, Any]:
    return {"kind": "sensors", "tilings": 4, "tiles": 4, "size": 256,
            "sensors": [{"sensor": s, "low": lo, "high": hi} for s, lo, hi in sensors]}  # fmt: skip


GYM: dict[str, dict[str, Any]] = {
    "MountainCar-v0": tiled(("position", -1.2, 0.6), ("velocity", -0.07, 0.07)),
    "Acrobot-v1": tiled(("cos1", -1, 1), ("omega1", -12.6, 12.6)),
    "CartPole-v1": tiled(("pole_angle", -0.42, 0.42), ("cart_velocity", -3, 3)),
}


def gym_spec(env_id: str, **extra: Any) -> RunSpec:
    first = GYM[env_id]["sensors"][0]["sensor"]
    return resolve_world(RunSpec.model_validate(
        {
            "world": {"kind": "gymnasium", "id": env_id, **extra.pop("world", {})},
            "features": GYM[env_id],
            "demons": [
                {"name": "next", "learner": "td", "policy": "uniform", "cumulant": {"sensor": first}, "discount": 0.5},
                {"name": "ends", "learner": "gq", "policy": "uniform", "outcome": {"sensor": "terminated"},
                 "discount": 0.9},
            ],
            **extra,
        }
    ))  # fmt: skip


@pytest.mark.parametrize("env_id", GYM)
def test_every_gymnasium_world_keeps_the_contract(env_id: str) -> None:
    check_world(gym_spec(env_id), steps=400)


def test_a_stream_world_keeps_the_contract() -> None:
    spec = RunSpec.model_validate(
        {
            "world": {"kind": "stream", "actions": 5, "sensors": [{"name": "light", "low": 0, "high": 1},
                                                                  {"name": "motor", "low": -2, "high": 2}]},
            "features": tiled(("light", 0, 1), ("motor", -2, 2)),
            "demons": [{"name": "light_soon", "learner": "gq", "cumulant": {"sensor": "light"}, "discount": 0.8}],
        }
    )  # fmt: skip
    check_world(spec)


def test_the_contract_check_catches_a_lying_terminated_sensor(monkeypatch: pytest.MonkeyPatch) -> None:
    real = GymWorld.step

    def lying(self: GymWorld, action: int) -> tuple[np.ndarray, bool, bool]:
        sensors, terminated, truncated = real(self, action)
        sensors[-2] = 1.0  # says terminated when the environment did not
        return sensors, terminated, truncated

    monkeypatch.setattr(GymWorld, "step", lying)
    with pytest.raises(WorldCheckError, match="terminated / truncated sensors disagree"):
        check_world(gym_spec("MountainCar-v0"), steps=20)


def test_sensors_are_named_with_ranges_and_actions_counted() -> None:
    world = gym_spec("Acrobot-v1").world
    assert world.sensor_names() == ["cos1", "sin1", "cos2", "sin2", "omega1", "omega2", "reward", "terminated",
                                    "truncated"]  # fmt: skip
    assert world.num_actions() == 3
    assert world.sensor_bounds()["omega1"] == pytest.approx((-4 * np.pi, 4 * np.pi))
    cartpole = gym_spec("CartPole-v1").world
    assert cartpole.num_actions() == 2
    assert cartpole.sensor_bounds()["cart_velocity"] == (-3.0, 3.0)  # documented range, the space is unbounded


def errors_of(data: dict[str, Any]) -> list[tuple[tuple[Any, ...], str]]:
    """The errors of validating a spec and resolving its world (where a Gymnasium world's sensors are checked)."""
    with pytest.raises(ValidationError) as info:
        resolve_world(RunSpec.model_validate(data))
    return [(e["loc"], e["msg"]) for e in info.value.errors()]


def test_an_id_not_installed_or_an_unsupported_space_is_an_error_at_world_id() -> None:
    [(loc, msg)] = errors_of({"world": {"kind": "gymnasium", "id": "NoSuchCar-v9"}})
    assert loc == ("world", "id") and "no installed Gymnasium environment 'NoSuchCar-v9'" in msg
    [(loc, msg)] = errors_of({"world": {"kind": "gymnasium", "id": "Pendulum-v1"}})
    assert loc == ("world", "id") and "needs a Discrete one" in msg
    [(loc, _)] = errors_of({"world": {"kind": "gymnasium", "id": "os:system"}})  # never imports a module
    assert loc == ("world", "id")


def test_validating_a_gymnasium_spec_makes_no_environment(monkeypatch: pytest.MonkeyPatch) -> None:
    """Validation leaves the sensors to `resolve_world` (horde.worlds), which makes the environment once."""
    import gymnasium

    from horde.worlds import gym_spaces

    gym_spaces._describe.cache_clear()  # so that resolving makes it here, whatever ran before
    made: list[str] = []
    real = gymnasium.make
    monkeypatch.setattr(gymnasium, "make", lambda env_id, **kw: made.append(env_id) or real(env_id, **kw))
    spec = RunSpec.model_validate(
        {"world": {"kind": "gymnasium", "id": "CartPole-v1"}, "features": {"kind": "constant"}}
    )
    assert made == [] and not spec.world.resolved
    with pytest.raises(ValueError, match="not resolved yet"):
        spec.world.sensor_names()
    resolved = resolve_world(spec)
    assert made == ["CartPole-v1"] and resolved.world.resolved and resolved.world.num_actions() == 2
    assert resolved.world.sensor_names()[0] == "cart_position"
    # resolving adds nothing to the spec: the same fields are the same spec (a served scenario, a snapshot's)
    assert resolved == spec and hash(resolved.world) == hash(spec.world)
    assert resolved.world != spec.world.model_copy(update={"max_steps": 10})


def test_policies_and_features_must_fit_the_world() -> None:
    base = {"world": {"kind": "gymnasium", "id": "MountainCar-v0"}, "features": GYM["MountainCar-v0"]}
    [(_, msg)] = errors_of({**base, "demons": [{"name": "d", "policy": {"kind": "fixed",
                                                                          "probabilities": [0.25] * 4}}]})  # fmt: skip
    assert "probabilities has 4 entries; the world has 3 actions" in msg
    [(_, msg)] = errors_of({**base, "features": {"kind": "stripes"}, "demons": [{"name": "d"}]})
    assert "kind 'stripes' codes grid positions" in msg
    [(_, msg)] = errors_of({**base, "behaviour": {"kind": "sign", "sensor": "speed", "actions": [0, 2]}})
    assert "sign reads unknown sensor 'speed'" in msg
    [(_, msg)] = errors_of({"behaviour": {"kind": "sign", "sensor": "x", "actions": [0, 2]}})
    assert "a sign policy needs a world fed from outside" in msg


def test_a_grid_world_keeps_its_error_locations_and_its_dump() -> None:
    assert errors_of({"world": {"widht": 3}})[0][0] == ("world", "widht")
    assert "kind" not in RunSpec().model_dump()["world"]
    assert RunSpec.model_validate({"world": {"kind": "grid", "width": 300}}).world.width == 300


def test_sign_policy_by_hand() -> None:
    np.testing.assert_allclose(sign_policy(0.01, (0, 2), 0.3, 3), [0.1, 0.1, 0.8])
    np.testing.assert_allclose(sign_policy(-0.01, (0, 2), 0.3, 3), [0.8, 0.1, 0.1])


def test_a_sign_behaviour_gives_exact_probabilities_and_the_same_seed_the_same_run() -> None:
    spec = gym_spec("MountainCar-v0", behaviour={"kind": "sign", "sensor": "velocity", "actions": [0, 2],
                                                  "epsilon": 0.3})  # fmt: skip
    one, two = GymAgent(spec), GymAgent(spec)
    for _ in range(50):
        velocity = one.sensors[1]
        expected = sign_policy(velocity, (0, 2), 0.3, 3)
        np.testing.assert_allclose(one.behaviour_probs(), expected)
        assert one.step().same(two.step())
    np.testing.assert_array_equal(one.learner.prediction(), two.learner.prediction())


def test_truncation_bootstraps_and_termination_does_not() -> None:
    """The time limit ends an episode as truncated; its last transition keeps its continuation (0.5 here),
    while a terminated one has continuation 0 (read right after learning, before the next episode starts)."""
    spec = gym_spec("MountainCar-v0", world={"max_steps": 3})
    agent = GymAgent(spec)
    assert [agent.step().truncated for _ in range(3)] == [False, False, True]
    for terminated, truncated, expected in ((False, True, 0.5), (True, False, 0.0)):
        loop = Learner(Horde(spec))
        loop.observe(agent.sensors)
        loop.learn(agent.sensors, [1], [1 / 3], terminated=terminated, truncated=truncated)
        assert loop.horde_state().gamma[loop.horde.index["next"]] == expected


def test_a_control_demon_drives_a_gymnasium_world_over_its_three_actions() -> None:
    spec = RunSpec.model_validate(
        {
            "world": {"kind": "gymnasium", "id": "MountainCar-v0"},
            "features": GYM["MountainCar-v0"],
            "behaviour": {"kind": "epsilon_greedy", "demon": "control", "epsilon": 0.3},
            "demons": [{"name": "control", "learner": "gq", "policy": "greedy", "cumulant": {"sensor": "reward"}}],
        }
    )
    agent = GymAgent(spec)
    for _ in range(200):
        probs = agent.behaviour_probs()
        q = agent.learner.q()[agent.horde.index["control"]]  # [3]
        greedy = q >= q.max() - 1e-12
        np.testing.assert_allclose(probs, 0.1 + 0.7 * greedy / greedy.sum())  # epsilon / 3 + (1 - epsilon) greedy
        agent.step()
    assert np.ptp(agent.learner.q()[agent.horde.index["control"]]) > 0, "the control demon's action values moved"
