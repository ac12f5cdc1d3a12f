"""The textbooks' chain worlds (Sutton & Barto 2018, examples 6.2, 7.1 and 9.1; Boyan 2002): names, models,
registration.

Every chain is a Gymnasium environment with one action (the walk is not controlled), a discrete observation
`state` (the state's number, terminal states included, as the book numbers them) and terminal states:

* `horde/RandomWalk5-v0`: states 1..5, start 3; left end (0) reward 0, right end (6) reward +1 (example 6.2,
  and Sutton et al. 2009's five-state walk);
* `horde/RandomWalk19-v0`: states 1..19, start 10; left end -1, right end +1 (example 7.1, figures 12.3-12.8);
* `horde/RandomWalk1000-v0`: states 1..1000, start 500; each step jumps 1 to 100 states left or right
  (uniformly), past an end terminates there: -1 left, +1 right (example 9.1);
* `horde/BoyanChain-v0`: Boyan's chain (Boyan 2002, as Sutton et al. 2009 use it): states 12 down to 1, start
  12; from a state >= 2 the chain moves 1 or 2 states on (probability 1/2 each), reward -3; from state 1 it
  ends in state 0 with reward -2. Its true values are -2 s.

A random walk's number of states may be set (`world.states`, 3 to MAX_CHAIN_STATES): its start is the middle.
`model(id, states)` gives a chain's (or Baird's star's) transitions: every state's value and every TD fixed
point is a linear solve over them (`horde.worlds.state_values`). `register()` registers every world of this
package (Baird's star too) with Gymnasium; the environments' classes are in `horde.worlds.chain_env`.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Any

import numpy as np

from horde.spec.worlds import MAX_CHAIN_STATES
from horde.worlds.baird import BAIRD_ID, DASHED, SOLID, UPPER

__all__ = ["CHAINS", "MAX_CHAIN_STATES", "Model", "chain_kwargs", "model", "register"]


@dataclass(frozen=True)
class ChainInfo:
    """A registered chain: its environment's class and arguments, and what the spec may change."""

    entry: str
    kwargs: dict[str, Any]
    sized: bool  # whether `world.states` may set its number of states
    rewards: tuple[float, float]  # the lowest and highest reward


CHAINS: dict[str, ChainInfo] = {
    "horde/RandomWalk5-v0": ChainInfo("RandomWalkEnv", {"states": 5, "left_reward": 0.0}, True, (0.0, 1.0)),
    "horde/RandomWalk19-v0": ChainInfo("RandomWalkEnv", {"states": 19}, True, (-1.0, 1.0)),
    "horde/RandomWalk1000-v0": ChainInfo("RandomWalkEnv", {"states": 1000, "jump": 100}, True, (-1.0, 1.0)),
    "horde/BoyanChain-v0": ChainInfo("BoyanChainEnv", {}, False, (-3.0, 0.0)),
}
BOYAN_STATES = 12
# The registered time limit: far beyond any episode these walks take (the 1000-state walk's mean is about 70
# steps, the 19-state walk's 100), there so that a live run's snapshots find the step count a limit keeps.
EPISODE_LIMIT = 1_000_000


def register() -> None:
    """Register the chains and Baird's star with Gymnasium (once; later calls do nothing)."""
    import gymnasium as gym

    from horde.worlds.baird import register as register_baird

    register_baird()
    for env_id, info in CHAINS.items():
        if env_id not in gym.registry:
            gym.register(id=env_id, entry_point=f"horde.worlds.chain_env:{info.entry}", kwargs=dict(info.kwargs),
                         max_episode_steps=EPISODE_LIMIT)  # fmt: skip


def chain_kwargs(env_id: str, states: int | None) -> dict[str, Any]:
    """The arguments `gym.make` passes for a world's `states` (none when it is left out).

    Raises:
        ValueError: `states` set for a world whose number of states is fixed.
    """
    if states is None:
        return {}
    info = CHAINS.get(env_id)
    if info is None or not info.sized:
        sized = ", ".join(k for k, v in CHAINS.items() if v.sized)
        raise ValueError(f"world {env_id!r} has a fixed number of states; states belongs to {sized}")
    return {"states": states}


@dataclass(frozen=True)
class Model:
    """A discrete world's transitions, K of them, from its N non-terminal states.

    `states` [N] are their observation numbers, in order; `start` [N] the distribution of an episode's first
    state. Transition k leaves state index src[k] under action act[k] with probability prob[k], gives reward
    reward[k], and lands in state index dst[k] (-1: a terminal state) observed as obs[k].
    """

    states: np.ndarray  # [N] int
    start: np.ndarray  # [N]
    num_actions: int
    src: np.ndarray  # [K] int
    act: np.ndarray  # [K] int
    prob: np.ndarray  # [K]
    dst: np.ndarray  # [K] int, -1 terminal
    obs: np.ndarray  # [K] the observation after
    reward: np.ndarray  # [K]

    @property
    def terminated(self) -> np.ndarray:
        return self.dst < 0


def _model(states: list[int], start: int, num_actions: int, rows: list[tuple[int, int, float, int, float]],
           terminal: set[int]) -> Model:  # fmt: skip
    """rows: (from state, action, probability, to state, reward) by observation numbers."""
    index = {s: i for i, s in enumerate(states)}
    merged: dict[tuple[int, int, int, float], float] = {}
    for s, a, p, t, r in rows:
        merged[(s, a, t, r)] = merged.get((s, a, t, r), 0.0) + p
    keys = list(merged)
    first = np.zeros(len(states))
    first[index[start]] = 1.0
    return Model(
        states=np.array(states, dtype=np.int64),
        start=first,
        num_actions=num_actions,
        src=np.array([index[k[0]] for k in keys], dtype=np.int64),
        act=np.array([k[1] for k in keys], dtype=np.int64),
        prob=np.array([merged[k] for k in keys]),
        dst=np.array([-1 if k[2] in terminal else index[k[2]] for k in keys], dtype=np.int64),
        obs=np.array([k[2] for k in keys], dtype=float),
        reward=np.array([k[3] for k in keys]),
    )


def random_walk_model(states: int = 19, jump: int = 1, left_reward: float = -1.0, right_reward: float = 1.0) -> Model:
    """The random walk's transitions (see the module)."""
    rows = []
    for s in range(1, states + 1):
        for direction in (-1, 1):
            for d in range(1, jump + 1):
                t = min(max(s + direction * d, 0), states + 1)
                reward = left_reward if t == 0 else right_reward if t == states + 1 else 0.0
                rows.append((s, 0, 0.5 / jump, t, reward))
    return _model(list(range(1, states + 1)), (states + 1) // 2, 1, rows, {0, states + 1})


def boyan_model() -> Model:
    """Boyan's chain's transitions (see the module)."""
    rows = [(1, 0, 1.0, 0, -2.0)]
    for s in range(2, BOYAN_STATES + 1):
        rows += [(s, 0, 0.5, s - 1, -3.0), (s, 0, 0.5, s - 2, -3.0)]
    return _model(list(range(BOYAN_STATES, 0, -1)), BOYAN_STATES, 1, rows, {0})


def baird_model() -> Model:
    """Baird's star: dashed to one of the six upper states, solid to the lower one, reward 0, never ending."""
    rows = []
    for s in range(UPPER + 1):
        rows += [(s, DASHED, 1.0 / UPPER, t, 0.0) for t in range(UPPER)]
        rows.append((s, SOLID, 1.0, UPPER, 0.0))
    model = _model(list(range(UPPER + 1)), 0, 2, rows, set())
    return Model(**{**model.__dict__, "start": np.full(UPPER + 1, 1.0 / (UPPER + 1))})


@functools.lru_cache(maxsize=16)
def model(env_id: str, states: int | None = None) -> Model | None:
    """The transitions of a registered chain (or Baird's star); None for any other world. Kept once made (the
    1000-state walk's takes about half a second); its arrays are read, never written."""
    if env_id == BAIRD_ID:
        return baird_model()
    info = CHAINS.get(env_id)
    if info is None:
        return None
    if info.entry == "BoyanChainEnv":
        return boyan_model()
    kwargs = {**info.kwargs, **chain_kwargs(env_id, states)}
    return random_walk_model(**kwargs)
