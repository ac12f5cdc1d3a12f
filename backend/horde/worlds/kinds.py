"""One way in for every simulated world kind: `Simulation(spec)` and `run_protocol(spec)` (the public API's).

The grid world is simulated inside the compiled loop (`horde.core.simulation.Simulation`, here
`GridSimulation`); a Gymnasium world is stepped in Python (`GymSimulation`, whose agent feeds the same engine).
Both step, read and restore through the same methods (`run`, `predictions`, `horde`, `horde_state`, `episode`,
`total_steps`), so a script runs either without knowing which. A stream world has no simulation: its records
come from outside (`horde.worlds.log_run.learn_log` learns a recorded log).
"""

from __future__ import annotations

import numpy as np

from horde.core.experiment import Progress, ProtocolResult
from horde.core.experiment import run_protocol as run_grid_protocol
from horde.core.simulation import Simulation as GridSimulation
from horde.core.source import Source
from horde.spec import RunSpec
from horde.worlds.gym_simulation import GymSimulation
from horde.worlds.protocol import GymProtocolResult, run_gym_protocol

AnySimulation = Source  # every source's one face (horde.core.source)
STREAM_HAS_NO_SIMULATION = (
    "a stream world has no simulation: its records come from outside; learn a recorded log with "
    "horde.learn_log(spec, path), or push records to a server's POST /api/streams"
)


def Simulation(spec: RunSpec, rng: np.random.Generator | None = None) -> AnySimulation:  # noqa: N802 (a constructor)
    """The agent, its world and its Horde for the spec's world kind, seeded from `rng` (default: spec.seed).

    Raises:
        ValueError: a stream world (STREAM_HAS_NO_SIMULATION), or a spec that cannot run.
    """
    if spec.world.kind == "gymnasium":
        return GymSimulation(spec, rng)
    if spec.world.kind == "stream":
        raise ValueError(STREAM_HAS_NO_SIMULATION)
    return GridSimulation(spec, rng)


def run_protocol(spec: RunSpec, progress: Progress | None = None) -> ProtocolResult | GymProtocolResult:
    """The spec's protocol: on the grid its trials against the Monte-Carlo truth (`ProtocolResult`); on a
    Gymnasium world learning, then each prediction beside realised returns (`GymProtocolResult`, as `horde run`).

    Raises:
        ValueError: a stream world.
    """
    if spec.world.kind == "gymnasium":
        return run_gym_protocol(spec, progress)
    if spec.world.kind == "stream":
        raise ValueError(STREAM_HAS_NO_SIMULATION)
    return run_grid_protocol(spec, progress)
