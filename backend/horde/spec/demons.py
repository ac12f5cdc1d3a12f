"""Demons (DESIGN sections 4 and 5): a question (policy, cumulant, outcome, continuation) and its answer
(features, learner, step sizes), and the run's learning defaults.

A demon's learner is one of those the engine declares (`horde.spec.learners`, filled by
`horde.core.learners`); its step-size mode and its own `parameters` are checked against that declaration.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import Field, field_validator, model_validator

from horde.spec.base import MAX_EXPR_NODES, MAX_FEATURES, Finite, Model, Name, Probability, field_error
from horde.spec.expressions import Expr, expr_size, raw_expr_problem
from horde.spec.features import FeatureSpec
from horde.spec.learners import learner_info, learner_names, step_size_problem
from horde.spec.policies import OWN_VALUE_POLICIES, PolicySpec

StepSize = Literal["constant", "autostep", "tidbd"]
Dtype = Literal["float64", "float32"]
MetaStep = Annotated[float, Field(ge=0.0, le=1.0, allow_inf_nan=False)]
AutostepTau = Annotated[float, Field(ge=1.0, le=1e9, allow_inf_nan=False)]
StepSizeValue = Annotated[float, Field(ge=0.0, le=10.0, allow_inf_nan=False)]
MAX_PARAMETERS = 16


def _learner_choices(schema: dict[str, Any]) -> None:
    """The API schema lists the declared learners (read when the schema is made, after they registered)."""
    schema["enum"] = list(learner_names())


def demon_step_size(demon: DemonSpec, learning: LearningSpec) -> tuple[str, float]:
    """A demon's step-size mode and meta step size: its own, else [learning]'s where its learner has that mode."""
    mode = demon.step_size
    if mode is None:
        mode = learning.step_size if step_size_problem(demon.learner, learning.step_size) is None else "constant"
    meta = demon.meta_step if demon.meta_step is not None else learning.meta_step
    return mode, meta


def demon_lambda(demon: DemonSpec, learning: LearningSpec) -> float:
    """A demon's lambda: its own, else [learning]'s where its learner has a form with traces, else 0."""
    if demon.lambda_ is not None:
        return float(demon.lambda_)
    return float(learning.lambda_) if learner_info(demon.learner).traces else 0.0


class DemonSpec(Model):
    """A question (policy, cumulant, outcome, continuation) and its answer (features, learner, step sizes)."""

    name: Name
    policy: PolicySpec = Field(default_factory=PolicySpec)
    cumulant: Expr = 0.0
    outcome: Expr = 0.0
    continuation: Expr = 1.0
    discount: Probability = 1.0
    learner: str = Field(
        default="gq",
        json_schema_extra=_learner_choices,
        description="gq: action values (GQ(lambda)); the others learn state values (GET /api/learners lists them)",
    )
    features: FeatureSpec | None = Field(default=None, description="defaults to the run's features")
    lambda_: Probability | None = Field(default=None, alias="lambda")
    alpha: StepSizeValue | None = Field(
        default=None, description="step size before division by the number of active features"
    )
    alpha_w: StepSizeValue | None = Field(
        default=None, description="step size of the secondary weights, also divided by the active count"
    )
    parameters: dict[Name, Finite] | None = Field(
        default=None,
        max_length=MAX_PARAMETERS,
        description="the learner's own numbers beyond alpha, alpha_w and lambda, as it declares them (GET "
        "/api/learners); each defaults to its declared value",
    )
    reset: Literal["never", "episode"] = "never"
    step_size: StepSize | None = Field(
        default=None,
        description="constant (alpha as given), autostep or tidbd (per-weight step sizes adapted online, "
        "starting from alpha); defaults to the run's [learning] step_size",
    )
    meta_step: MetaStep | None = Field(
        default=None, description="meta step size of autostep (mu) or tidbd (theta); defaults to [learning]"
    )
    initial_weights: list[Finite] | None = Field(
        default=None,
        max_length=MAX_FEATURES,
        description="the weights the demon starts from (and a run reset restores), one per feature (gq: per "
        "feature of every action's block, action by action); default all 0",
    )

    @field_validator("cumulant", "outcome", "continuation", mode="before")
    @classmethod
    def _bounded_expr(cls, value: Any) -> Any:
        problem = raw_expr_problem(value)
        if problem is not None:
            raise ValueError(f"this expression is {problem}" if "nested" in problem else f"this expression {problem}")
        return value

    @field_validator("learner")
    @classmethod
    def _declared(cls, learner: str) -> str:
        learner_info(learner)  # raises naming the known learners
        return learner

    @model_validator(mode="after")
    def _consistent(self) -> DemonSpec:
        for field in ("cumulant", "outcome", "continuation"):
            if expr_size(getattr(self, field)) > MAX_EXPR_NODES:
                raise ValueError(f"{field} has more than {MAX_EXPR_NODES} nodes")
        info = learner_info(self.learner)
        if not info.action_values and self.policy.kind in OWN_VALUE_POLICIES:
            raise ValueError(
                f"a {self.policy.kind} target policy needs action values: use learner 'gq', not {self.learner!r}"
            )
        if self.step_size is not None and (problem := step_size_problem(self.learner, self.step_size)):
            raise ValueError(problem)
        if not info.traces and self.lambda_:
            raise field_error("DemonSpec", ("lambda",), "lambda_zero_only",
                              f"learner {self.learner!r} is defined for lambda = 0 only (no published form with "
                              "traces)", self.lambda_)  # fmt: skip
        if self.initial_weights is not None and self.reset == "episode":
            raise ValueError("initial_weights and reset = 'episode' do not go together: a demon that forgets its "
                             "weights at every episode start starts each episode from 0")  # fmt: skip
        for name, value in (self.parameters or {}).items():
            declared = info.parameter(name)
            if declared is None:
                known = ", ".join(p.name for p in info.parameters) or "none"
                raise field_error("DemonSpec", ("parameters", name), "unknown_parameter",
                                  f"learner {self.learner!r} takes no parameter {name!r} (its parameters: {known})",
                                  value)  # fmt: skip
            if not declared.low <= value <= declared.high:
                raise field_error("DemonSpec", ("parameters", name), "parameter_range",
                                  f"{name} of {self.learner!r} must lie in [{declared.low:g}, {declared.high:g}]",
                                  value)  # fmt: skip
        return self

    def parameter(self, name: str) -> float:
        """One of the learner's own parameters: the demon's, else the declared default."""
        if self.parameters and name in self.parameters:
            return float(self.parameters[name])
        declared = learner_info(self.learner).parameter(name)
        if declared is None:
            raise KeyError(f"learner {self.learner!r} has no parameter {name!r}")
        return declared.default

    @property
    def action_values(self) -> bool:
        """Whether the demon learns action values (its learner's declaration says so)."""
        return learner_info(self.learner).action_values


class LearningSpec(Model):
    """Defaults for demons that do not set their own, chosen by `studies/stepsizes.toml` (see README)."""

    lambda_: Probability = Field(default=0.9, alias="lambda")
    alpha: StepSizeValue = 0.03
    alpha_w: StepSizeValue = 0.0001
    step_size: StepSize = Field(
        default="constant",
        description="the step-size mode of demons that set none; an adaptive mode applies only to the learners "
        "it is defined for (td), the others keep constant step sizes",
    )
    meta_step: MetaStep = Field(default=0.01, description="autostep's mu and tidbd's theta (meta step size)")
    autostep_tau: AutostepTau = Field(
        default=10_000.0, description="autostep's time scale tau of its normaliser v (Mahmood et al. 2012: 1e4)"
    )
    dtype: Dtype = Field(
        default="float64",
        description="the numbers of the weights, secondary weights, traces and per-weight step sizes: float32 "
        "halves their memory and the bytes a step moves (sums are still taken in float64)",
    )
