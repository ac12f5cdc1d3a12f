"""Operations on a core `Simulation` that the run layer needs and the core does not offer (yet).

- `freeze`: a deep copy of a Horde state, safe to hand to other threads (the fast engine's
  `horde_state` holds live views of its weight buffers).
- `set_returns`: restore the episode returns (read-only properties of `Simulation`).
- `rebuild`: the same agent with a changed set of demons, every remaining demon's weights kept.

`set_returns` writes the simulation's private return buffers; a public setter in the core would
replace it.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from horde.core.horde import HordeState
from horde.core.simulation import Simulation
from horde.spec import RunSpec


def _copy(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        return value.copy()
    if isinstance(value, tuple):
        items = [_copy(item) for item in value]
        return type(value)(*items) if hasattr(value, "_fields") else tuple(items)
    return value


def freeze(state: HordeState) -> HordeState:
    """A copy of every array of the state (nothing shared with the simulation)."""
    frozen: HordeState = _copy(state)
    return frozen


def set_returns(sim: Simulation, episode_return: float, last_return: float) -> None:
    """Set the return of the episode under way and of the last finished one."""
    loop = getattr(sim, "_loop", None)
    if loop is not None:
        loop.returns[:] = (episode_return, last_return)
    else:
        sim._numpy_return = [episode_return, last_return]


def rebuild(sim: Simulation, spec: RunSpec) -> Simulation:
    """A simulation of `spec` (new demons) that continues `sim`: same agent, generator and counters.

    Every demon that `sim` also had keeps its weights (`Horde.carry_over`); traces restart as at an
    episode start. The generator's state is left exactly as it was.
    """
    rng = sim.rng
    rng_state = rng.bit_generator.state
    new = Simulation(spec, rng, sim.engine)  # draws a start, so the generator's state is put back below
    rng.bit_generator.state = rng_state
    world_state = sim.world_state
    x, y = sim.position
    new.world_state = world_state
    new.horde_state = new.horde.carry_over(sim.horde, sim.horde_state, x, y)
    new.episode = sim.episode
    new.total_steps = sim.total_steps
    set_returns(new, sim.episode_return, sim.last_return)
    return new
