"""What a Gymnasium environment's spaces mean as Horde sensors and actions.

`describe(id)` makes the environment once (cached), checks that its observation space is a flat `Box`
(or a `Discrete`: one sensor, `state`, the state's number) and its action space a `Discrete` starting at
0, and names the observation's components. The
classic-control environments (which ship with `gymnasium`) get the names and ranges of their
documentation; where a bound is infinite the range given is the documented typical range (the tile
coder clips beyond it). Any other environment's components are `obs0`, `obs1`, ... with the space's
bounds where finite.

`resolve_world(spec)` hands a run spec's Gymnasium world its sensors and actions (validation makes no
environment: `horde.spec.worlds`), then checks what needs them (`horde.spec.run.check_world_fit`).
"""

from __future__ import annotations

import math
from functools import lru_cache
from typing import Any

import numpy as np
from pydantic import ValidationError
from pydantic_core import InitErrorDetails, PydanticCustomError

from horde.spec import GymnasiumWorldSpec, RunSpec, SensorRange, validate_world_fit
from horde.worlds.chains import CHAINS, chain_kwargs

# Documented names and ranges of the classic-control observations, and each environment's reward range
# (an episode's first state reads reward 0).
_DOCUMENTED: dict[str, tuple[list[tuple[str, float, float]], tuple[float, float]]] = {
    "MountainCar": ([("position", -1.2, 0.6), ("velocity", -0.07, 0.07)], (-1.0, 0.0)),
    "Acrobot": (
        [
            ("cos1", -1.0, 1.0),
            ("sin1", -1.0, 1.0),
            ("cos2", -1.0, 1.0),
            ("sin2", -1.0, 1.0),
            ("omega1", -4 * math.pi, 4 * math.pi),
            ("omega2", -9 * math.pi, 9 * math.pi),
        ],
        (-1.0, 0.0),
    ),
    "Baird": ([("state", 0.0, 6.0)], (-1.0, 1.0)),  # horde.worlds.baird: every reward is 0
    "CartPole": (
        [
            ("cart_position", -4.8, 4.8),
            ("cart_velocity", -3.0, 3.0),
            ("pole_angle", -0.418, 0.418),
            ("pole_angular_velocity", -3.5, 3.5),
        ],
        (0.0, 1.0),
    ),
}


class GymSpaceError(ValueError):
    """The environment is not installed, or its spaces are not a flat Box and a Discrete."""


def _family(env_id: str) -> str:
    return env_id.split("/")[-1].split("-v")[0]


@lru_cache(maxsize=64)
def _describe(env_id: str, kwargs: tuple[tuple[str, int], ...] = ()) -> tuple[tuple[SensorRange, ...], int]:
    import gymnasium as gym
    from gymnasium import spaces

    from horde.worlds.chains import register

    register()  # horde/Baird-v0 and the chains

    try:
        env = gym.make(env_id, **dict[str, Any](kwargs))
    except Exception as exc:  # gymnasium raises several kinds: unknown name, version, missing dependency
        raise GymSpaceError(f"no installed Gymnasium environment {env_id!r}: {exc}") from None
    try:
        obs, act = env.observation_space, env.action_space
    finally:
        env.close()
    if not isinstance(act, spaces.Discrete):
        raise GymSpaceError(f"{env_id!r} has action space {act}; Horde Lab needs a Discrete one")
    if int(act.start) != 0:
        raise GymSpaceError(f"{env_id!r} numbers its actions from {int(act.start)}; Horde Lab needs 0")
    if int(act.n) > 64:
        raise GymSpaceError(f"{env_id!r} has {int(act.n)} actions, more than 64")
    if isinstance(obs, spaces.Discrete):  # one sensor: the state's number
        if int(obs.n) > 4096:
            raise GymSpaceError(f"{env_id!r} has {int(obs.n)} discrete states, more than 4096")
        first = int(obs.start)
        state = SensorRange(name="state", low=first, high=first + max(int(obs.n) - 1, 1))
        rewards = CHAINS[env_id].rewards if env_id in CHAINS else None
        rewards = rewards or _DOCUMENTED.get(_family(env_id), ([], (-math.inf, math.inf)))[1]
        return (state, *_endings(rewards)), int(act.n)
    if not isinstance(obs, spaces.Box) or len(obs.shape) != 1:
        raise GymSpaceError(f"{env_id!r} has observation space {obs}; Horde Lab needs a flat Box or a Discrete")
    if obs.shape[0] > 1000:
        raise GymSpaceError(f"{env_id!r} observes {obs.shape[0]} components, more than 1000")
    documented, rewards = _DOCUMENTED.get(_family(env_id), ([], (-math.inf, math.inf)))
    if len(documented) != obs.shape[0]:
        documented = []
    sensors = []
    for i in range(obs.shape[0]):
        low, high = float(np.asarray(obs.low)[i]), float(np.asarray(obs.high)[i])
        name = documented[i][0] if documented else f"obs{i}"
        if documented:
            low = low if math.isfinite(low) else documented[i][1]
            high = high if math.isfinite(high) else documented[i][2]
        sensors.append(SensorRange(name=name, low=low if math.isfinite(low) else None,
                                   high=high if math.isfinite(high) else None))  # fmt: skip
    return (*sensors, *_endings(rewards)), int(act.n)


def _endings(rewards: tuple[float, float]) -> tuple[SensorRange, ...]:
    """The sensors after the observation's: reward (in its range, where known), terminated, truncated."""
    return (
        SensorRange(name="reward", low=rewards[0] if math.isfinite(rewards[0]) else None,
                    high=rewards[1] if math.isfinite(rewards[1]) else None),
        SensorRange(name="terminated", low=0.0, high=1.0),
        SensorRange(name="truncated", low=0.0, high=1.0),
    )  # fmt: skip


def describe(env_id: str, states: int | None = None) -> tuple[list[SensorRange], int]:
    """The sensors (observation components, then reward, terminated, truncated) and the number of actions;
    `states`: a random walk's number of states (`horde.worlds.chains`).

    Raises:
        GymSpaceError: the environment is not installed or its spaces are not supported (the message says which).
    """
    sensors, actions = _describe(env_id, tuple(chain_kwargs(env_id, states).items()))
    return list(sensors), actions


def resolve_world(spec: RunSpec) -> RunSpec:
    """The spec with its Gymnasium world's sensors and actions resolved and checked (other worlds: as it is).

    Raises:
        ValidationError: at `world.id` when the environment is not installed or its spaces are not supported;
            else as RunSpec validation names it (a demon reading an unknown sensor, a policy over other actions).
    """
    world = spec.world
    if not isinstance(world, GymnasiumWorldSpec) or world.resolved:
        return spec
    try:
        chain_kwargs(world.id, world.states)
    except ValueError as exc:  # states set where the world's number of states is fixed
        detail = InitErrorDetails(type=PydanticCustomError("world_states", str(exc)), loc=("world", "states"),
                                  input=world.states)  # fmt: skip
        raise ValidationError.from_exception_data("RunSpec", [detail]) from None
    try:
        sensors, actions = describe(world.id, world.states)
    except GymSpaceError as exc:  # a ValidationError at `world.id`, so that the 422 names the field
        detail = InitErrorDetails(type=PydanticCustomError("gymnasium_id", str(exc)), loc=("world", "id"),
                                  input=world.id)  # fmt: skip
        raise ValidationError.from_exception_data("RunSpec", [detail]) from None
    return validate_world_fit(spec.model_copy(update={"world": world.with_sensors(sensors, actions)}))
