"""Horde Lab: many predictions learned at once with the Horde architecture.

The public API, for running a Horde from Python without the server (examples/05_horde_in_python.py,
examples/08_any_world_in_python.py):

    spec = RunSpec.model_validate({...}) or load_scenario("scenarios/experiment1.toml")
    check_world(spec)                      # the world keeps the environment contract on both engines
    sim = Simulation(spec); sim.run(5000)  # one agent, its world, its demons; sim.predictions()
                                           # any simulated world: the grid (GridSimulation), a Gymnasium
                                           # environment or Baird's star (GymSimulation), same methods
    exact(sim.horde, sim.horde_state, "steps_to_end")   # the true answers on a lattice world
    result = run_protocol(spec)            # grid: the thesis' trials -> ProtocolResult;
                                           # Gymnasium: predictions beside realised returns -> GymProtocolResult
    log = learn_log(spec, "run.csv")       # a stream world learns a recorded log -> LogResult

Everything else (the server, the run store, the compiled kernels) is internal and may change.
"""

import horde.core.learners  # noqa: F401  (first: the engine's learners register with the spec)
from horde.core.check import WorldCheckError
from horde.core.evaluate import Lattice, Truth, exact, monte_carlo
from horde.core.experiment import DemonResult, ProtocolResult, TrialResult
from horde.core.learners import LearnerParams, LearnerState, update
from horde.core.learners import zeros as learner_zeros
from horde.core.simulation import Simulation as GridSimulation
from horde.core.simulation import StepResult
from horde.core.world import ImpossibleStartError
from horde.scenarios import ScenarioError, load_scenario, parse_scenario
from horde.spec import (
    BehaviourSpec,
    DemonFamily,
    DemonSpec,
    FeatureSpec,
    PolicySpec,
    ProtocolSpec,
    Region,
    RunSpec,
    WorldSpec,
)
from horde.worlds.check import check_world
from horde.worlds.gym_simulation import GymSimulation
from horde.worlds.kinds import AnySimulation, Simulation, run_protocol
from horde.worlds.log_run import LogDemon, LogResult, learn_log
from horde.worlds.protocol import GymDemonResult, GymProtocolResult

__all__ = [
    "AnySimulation",
    "BehaviourSpec",
    "DemonFamily",
    "DemonResult",
    "DemonSpec",
    "FeatureSpec",
    "GridSimulation",
    "GymDemonResult",
    "GymProtocolResult",
    "GymSimulation",
    "ImpossibleStartError",
    "Lattice",
    "LearnerParams",
    "LearnerState",
    "LogDemon",
    "LogResult",
    "PolicySpec",
    "ProtocolResult",
    "ProtocolSpec",
    "Region",
    "RunSpec",
    "ScenarioError",
    "Simulation",
    "StepResult",
    "TrialResult",
    "Truth",
    "WorldCheckError",
    "WorldSpec",
    "check_world",
    "exact",
    "learn_log",
    "learner_zeros",
    "load_scenario",
    "monte_carlo",
    "parse_scenario",
    "run_protocol",
    "update",
]
