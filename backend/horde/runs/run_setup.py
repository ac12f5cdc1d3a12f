"""Setting a run up: its simulation (seeded as the protocol's first trial) and the server's size limits."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pydantic import ValidationError

from horde.runs.errors import SpecError
from horde.spec import RunSpec
from horde.worlds.kinds import AnySimulation, Simulation


@dataclass(frozen=True)
class Limits:
    """Sizes the server accepts, beyond the bounds that the spec models enforce themselves."""

    max_runs: int = 32
    max_demons: int = 10_000
    max_weights: int = 12_000_000  # numbers in one weight array of all demons together (theta; w, e, h alike)
    max_step_request: int = 10_000  # steps of one POST /step
    history: int = 10_000  # rows of each run's history
    history_every: int = 1  # steps between two history rows at least
    history_interval: float = 0.005  # seconds between two history rows at least
    snapshot_every: float = 2.0  # seconds between snapshots of a running run (a hard kill loses at most this)
    events: int = 256
    evaluation_seconds: float = 30.0  # a Monte-Carlo evaluation (POST /evaluate) is given up after this long


def trial_rng(spec: RunSpec) -> np.random.Generator:
    """The generator of the protocol's first trial, as `horde.core.experiment.run_trial(spec, 0)` seeds it."""
    return np.random.default_rng([spec.seed, 0])


def weight_count(spec: RunSpec) -> int:
    """Numbers in the primary weights of all demons of a spec."""
    return sum((d.features or spec.features).state_size() * (4 if d.learner == "gq" else 1) for d in spec.demons)


def check_limits(spec: RunSpec, limits: Limits) -> None:
    """Raises SpecError (naming `demons`) when a spec is larger than this server runs."""
    if len(spec.demons) > limits.max_demons:
        raise SpecError.at(("body", "demons"), f"at most {limits.max_demons} demons per run (got {len(spec.demons)})")
    weights = weight_count(spec)
    if weights > limits.max_weights:
        raise SpecError.at(
            ("body", "demons"),
            f"the demons' weights would hold {weights} numbers; this server allows {limits.max_weights} per run",
        )


def new_simulation(spec: RunSpec) -> AnySimulation:
    """A fresh source of transitions for the spec's world, seeded like trial 0 of its protocol: the grid
    world's `Simulation`, or a `GymSimulation` for a Gymnasium environment.

    Raises:
        SpecError: the spec validates but cannot run (for example a start area that is all obstacle), or
            its world is a stream (whose records clients push: POST /api/streams).
    """
    if spec.world.kind == "stream":
        raise SpecError.at(("body", "world", "kind"), "a stream world learns the records its clients push: "
                                                      "create it with POST /api/streams")  # fmt: skip
    try:
        return Simulation(spec, trial_rng(spec))
    except ValidationError as exc:  # a Gymnasium world whose sensors the spec does not fit (resolved here)
        raise SpecError.from_validation(exc, ("body",)) from None
    except ValueError as exc:
        raise SpecError.at(("body",), f"the spec cannot run: {exc}") from None
