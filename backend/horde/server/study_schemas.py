"""The wire format of studies (POST/GET /api/studies): a study's progress and its results with bands.

The input is the study spec itself (`horde.studies.spec.StudySpec`, as in a study file). Non-finite
numbers travel as null.
"""

from __future__ import annotations

from datetime import datetime
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field

from horde.studies.spec import AxisSpec, AxisValue

MaybeFloat = float | None
StudyStatus = Literal["created", "running", "finished", "failed", "cancelled", "interrupted"]


class _Out(BaseModel):
    model_config = ConfigDict(frozen=True)


class BandOut(_Out):
    """A mean over runs per checkpoint with its 95 % bootstrap interval."""

    mean: list[MaybeFloat]
    low: list[MaybeFloat]
    high: list[MaybeFloat]


class StudyDemonOut(_Out):
    """One demon of one configuration: final error (the question's own units), its interval, its curve."""

    error: MaybeFloat
    ci_low: MaybeFloat
    ci_high: MaybeFloat
    auc: MaybeFloat = Field(description="mean error over the checkpoints after episode 0")
    curve: BandOut
    rupee: BandOut


class StudyConfigOut(_Out):
    """One configuration over its finished runs."""

    index: int
    axes: dict[str, AxisValue]
    runs: int
    best: bool = Field(description="the lowest final relative error of the study (never a diverged configuration)")
    diverged: bool = Field(
        description="a run diverged: its final relative error or AUC non-finite or above 1e6, or a measured demon "
        "frozen by the engine as diverged; its numbers are then not a fit"
    )
    truth: Literal["exact", "monte_carlo"]
    episodes: list[int] = Field(description="training episodes at each checkpoint")
    error: MaybeFloat = Field(description="final relative error: error / scale, mean over the demons")
    ci_low: MaybeFloat
    ci_high: MaybeFloat
    auc: MaybeFloat
    auc_low: MaybeFloat
    auc_high: MaybeFloat
    curve: BandOut = Field(description="relative error per checkpoint")
    returns: BandOut = Field(description="mean return of the episodes before each checkpoint")
    positive: BandOut | None = Field(
        default=None, description="control protocols: the share of test runs ending in a positive terminal"
    )
    demons: dict[str, StudyDemonOut]


class StudyOut(_Out):
    """A study and how far it has got."""

    id: str
    owner: str = Field(description="who started it: 'teacher', or the name of the student's token")
    name: str | None
    scenario: str | None = Field(description="the base run spec's name")
    status: StudyStatus
    message: str
    axes: list[AxisSpec]
    runs: int = Field(description="runs per configuration")
    episodes: int = Field(description="training episodes per run")
    configurations: int
    tasks: int = Field(description="configurations x runs")
    tasks_done: int
    seconds_left: MaybeFloat = Field(description="estimated from the pace so far (running studies only)")
    created_at: datetime
    updated_at: datetime


class StudyResultsOut(StudyOut):
    """A study with every configuration that has a finished run."""

    results: list[StudyConfigOut]
    warnings: list[str] = Field(
        description="what the results will not show on their own (gtd learning as td at alpha_w = 0)"
    )
