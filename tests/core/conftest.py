"""Shared fixtures of the core tests: `engine` runs a test on every engine the simulation offers."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from horde.core.simulation import Simulation
from horde.spec import RunSpec

from .engines import ENGINES, new_simulation


@pytest.fixture(params=ENGINES, ids=lambda engine: engine or "default")
def engine(request: pytest.FixtureRequest) -> str | None:
    return request.param


@pytest.fixture
def make_simulation(engine: str | None) -> Callable[..., Simulation]:
    """Simulation(spec, rng=None) on the engine under test."""

    def make(spec: RunSpec, rng: np.random.Generator | None = None) -> Simulation:
        return new_simulation(spec, engine, rng)

    return make
