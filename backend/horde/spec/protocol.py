"""The protocol of a run: trials x episodes x max steps, the stopping rule, evaluation and test runs; and the
thesis's numbers shown beside ours."""

from __future__ import annotations

from typing import Annotated

from pydantic import Field

from horde.spec.base import MAX_EPISODES, MAX_STEPS, MAX_TRIALS, Finite, Model, Name
from horde.spec.policies import BehaviourSpec


class StopRule(Model):
    """Stop a trial early once no weight moved by more than `tolerance` over `window` episodes."""

    window: int = Field(default=100, ge=1, le=MAX_EPISODES)
    tolerance: Annotated[float, Field(gt=0.0, allow_inf_nan=False)] = 1e-3


class EvaluationSpec(Model):
    """Monte-Carlo truth at the start point after each trial."""

    rollouts: int = Field(default=1000, ge=0, le=100_000)
    cap: int = Field(default=10_000, ge=1, le=MAX_STEPS, description="rollout length limit")
    demons: list[Name] | None = Field(default=None, description="which demons; default all prediction demons")
    states: int = Field(
        default=20,
        ge=1,
        le=1000,
        description="Gymnasium worlds: test states, from a run of the behaviour after learning",
    )


class TestSpec(Model):
    """Test runs after each trial: the behaviour below, no learning except reset-each-episode demons."""

    runs: int = Field(default=100, ge=1, le=100_000)
    behaviour: BehaviourSpec


class ProtocolSpec(Model):
    trials: int = Field(default=1, ge=1, le=MAX_TRIALS)
    episodes: int = Field(default=1000, ge=0, le=MAX_EPISODES)
    stop: StopRule | None = None
    evaluation: EvaluationSpec = Field(default_factory=EvaluationSpec)
    test: TestSpec | None = None


class Counts(Model):
    positive: int = Field(ge=0)
    negative: int = Field(ge=0)
    none: int = Field(ge=0)


class ThesisResults(Model):
    """The thesis's numbers, shown beside ours."""

    predictions: dict[Name, Finite] = Field(default_factory=dict)
    counts: Counts | None = None
