"""Warming the fork server up: the engine's compiled kernels loaded (or compiled) once, before any worker forks.

numba loads a kernel from its cache (or compiles it) at its first call in a process. The fork server calls
each kernel a run is likely to need on tiny runs, so that a forked worker starts with them loaded: the thesis
loop (a grid world, a control demon and its followers), the block engine of every learner and step-size
adaptation, and Monte-Carlo rollouts. Each run is small enough to take one thread (numba's thread pool must
not start in a process that forks: its children would inherit a pool without its threads).
"""

from __future__ import annotations

import logging
import time
from typing import Any

import numpy as np

from horde.core.evaluate import monte_carlo
from horde.core.simulation import Simulation
from horde.runs import session
from horde.runs.run_setup import new_simulation
from horde.scenarios import load_scenario, scenario_dir
from horde.spec import RunSpec

log = logging.getLogger(__name__)

LEARNERS = (("td", None), ("gtd", None), ("gq", None), ("true_online_td", None), ("true_online_gtd", None),
            ("etd", None), ("td", "autostep"), ("td", "tidbd"))  # fmt: skip
STEPS = 300


def _learners_spec() -> RunSpec:
    """The classroom world with one demon of every learner (and step-size adaptation) over tiles."""
    base = load_scenario(scenario_dir() / "classroom-offpolicy.toml").model_dump(by_alias=True)
    demons: list[dict[str, Any]] = []
    for i, (learner, step_size) in enumerate(LEARNERS):
        policy: Any = {"kind": "softmax", "temperature": 1.0} if learner == "gq" else "uniform"
        demon: dict[str, Any] = {"name": f"warm{i}", "learner": learner, "policy": policy, "cumulant": 1,
                                 "discount": 0.9}  # fmt: skip
        if step_size is not None:
            demon["step_size"] = step_size
        demons.append(demon)
    base.update(demons=demons, families=[], behaviour={"kind": "uniform"},
                features={"kind": "tiles", "tilings": 2, "tiles": 4})  # fmt: skip
    return RunSpec.model_validate(base)


def _specs() -> list[RunSpec]:
    folder = scenario_dir()
    return [load_scenario(folder / "experiment1.toml"), load_scenario(folder / "classroom-offpolicy.toml"),
            _learners_spec()]  # fmt: skip


def warm_up() -> float:
    """Call the kernels of the common runs once; the seconds it took. A spec that fails is logged and skipped."""
    began = time.perf_counter()
    for spec in _specs():
        try:
            sim = new_simulation(spec)
            if isinstance(sim, Simulation):
                sim.threads = 1
            sim.run(STEPS)
            name = sim.horde.names[0]
            monte_carlo(sim.horde, sim.view_state(), name, (50.0, 50.0), 2, 5, np.random.default_rng(0), None)
        except Exception as exc:  # a warm-up is an optimisation: a worker would compile what is missing
            log.warning("warming the kernels up on %r failed: %s", spec.name, exc)
    session._kernels_ready.set()
    return time.perf_counter() - began
