"""Baird's counterexample (Baird 1995; Sutton & Barto, 2nd ed., section 11.2): the star's names and registration.

Seven states: six upper ones (0 to 5) and a lower one (6). Two actions: `dashed` (0) moves to one of the
six upper states, uniformly; `solid` (1) moves to the lower state. The reward is 0 on every transition and
nothing terminates: the task is continuing (a run's `world.max_steps` may cut it into episodes, which only
restarts the traces). The observation is the state's number (`Discrete(7)`); the environment keeps it in
`unwrapped.state`, so that snapshots and Monte-Carlo rollouts can put it back.

`register()` (called wherever Gymnasium environments are made) registers it as `horde/Baird-v0`, the id a
scenario's `world.id` names (`scenarios/baird.toml`: its classic features and weights, the 6/7 dashed
behaviour and the always-solid target policy that make off-policy TD(lambda) diverge). The environment's
class is in `horde.worlds.baird_env`.
"""

from __future__ import annotations

BAIRD_ID = "horde/Baird-v0"
UPPER = 6  # states 0..5; state 6 is the lower one
DASHED, SOLID = 0, 1


def register() -> None:
    """Register `horde/Baird-v0` with Gymnasium (once; later calls do nothing). The environment's class lives in
    `horde.worlds.baird_env`, so that reading these names imports no Gymnasium."""
    import gymnasium as gym

    if BAIRD_ID not in gym.registry:
        gym.register(id=BAIRD_ID, entry_point="horde.worlds.baird_env:BairdEnv")
