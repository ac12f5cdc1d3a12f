"""The engines the simulation offers, for tests that run on each of them."""

from __future__ import annotations

import inspect

import numpy as np

from horde.core.simulation import Simulation
from horde.spec import RunSpec

# "numpy" is the readable vectorized engine (world.py + horde.py), "fast" the compiled one. A
# simulation without an `engine` argument has one engine only: None stands for it.
ENGINES: list[str | None] = ["numpy", "fast"] if "engine" in inspect.signature(Simulation).parameters else [None]
NUMPY_ENGINE: str | None = "numpy" if ENGINES != [None] else None


def new_simulation(spec: RunSpec, engine: str | None, rng: np.random.Generator | None = None) -> Simulation:
    """Simulation(spec, rng) on the named engine."""
    if engine is None:
        return Simulation(spec, rng)
    return Simulation(spec, rng, engine=engine)  # type: ignore[call-arg, arg-type]
