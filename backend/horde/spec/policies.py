"""Target policies of demons and the behaviour policy of a run (DESIGN section 4)."""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

from pydantic import Field, model_validator

from horde.spec.base import MAX_ACTIONS, Model, Name, Probability, SensorName

PolicyKind = Literal["uniform", "fixed", "greedy", "softmax", "epsilon_greedy", "of", "sign"]
OWN_VALUE_POLICIES = ("greedy", "softmax", "epsilon_greedy")


def _policy_shorthand(value: Any) -> Any:
    """Accept "uniform", "softmax", {of = "base"} besides the full {kind = ...} form."""
    if isinstance(value, str):
        return {"kind": value}
    if isinstance(value, dict) and "kind" not in value and set(value) == {"of"}:
        return {"kind": "of", "demon": value["of"]}
    return value


def _sign_fields(policy: PolicySpec | BehaviourSpec) -> None:
    """A "sign" policy names its sensor and its two actions; no other kind does."""
    if policy.kind == "sign" and (policy.sensor is None or policy.actions is None):
        raise ValueError("a sign policy names a sensor and actions = [action where negative, action where >= 0]")
    if policy.kind != "sign" and (policy.sensor is not None or policy.actions is not None):
        raise ValueError(f"sensor and actions belong to sign policies (this one is {policy.kind!r})")


class PolicySpec(Model):
    """A target policy. Shorthands: "uniform", "greedy", "softmax", {of = "demon"}."""

    kind: PolicyKind = "uniform"
    probabilities: list[Probability] | None = Field(
        default=None,
        min_length=1,
        max_length=MAX_ACTIONS,
        description="fixed: one per action of the world ([up, down, left, right] in the grid world)",
    )
    temperature: Annotated[float, Field(gt=0.0, le=1e6, allow_inf_nan=False)] = 1.0
    epsilon: Probability = 0.1
    demon: Name | None = Field(default=None, description="of: the demon whose policy this follows")
    sensor: SensorName | None = Field(default=None, description="sign: the sensor whose sign chooses the action")
    actions: list[Annotated[int, Field(ge=0, lt=MAX_ACTIONS)]] | None = Field(
        default=None, min_length=2, max_length=2, description="sign: [action where negative, action where >= 0]"
    )

    _shorthand = model_validator(mode="before")(_policy_shorthand)

    @model_validator(mode="after")
    def _fields(self) -> PolicySpec:
        _sign_fields(self)
        if self.kind == "fixed":
            if self.probabilities is None:
                raise ValueError("a fixed policy needs probabilities [up, down, left, right]")
            if not math.isclose(sum(self.probabilities), 1.0, abs_tol=1e-9):
                raise ValueError("fixed probabilities must sum to 1")
        elif self.probabilities is not None:
            raise ValueError("probabilities belong to fixed policies only")
        if self.kind == "of" and self.demon is None:
            raise ValueError("an 'of' policy names the demon it follows")
        if self.kind != "of" and self.demon is not None:
            raise ValueError(f"only 'of' policies name a demon (this one is {self.kind!r})")
        return self


class BehaviourSpec(Model):
    """The behaviour policy of a run: uniform, fixed, or greedy/softmax/epsilon_greedy over a control demon."""

    kind: Literal["uniform", "fixed", "greedy", "softmax", "epsilon_greedy", "sign"] = "uniform"
    demon: Name | None = None
    probabilities: list[Probability] | None = Field(default=None, min_length=1, max_length=MAX_ACTIONS)
    temperature: Annotated[float, Field(gt=0.0, le=1e6, allow_inf_nan=False)] = 1.0
    epsilon: Probability = 0.1
    sensor: SensorName | None = Field(default=None, description="sign: the sensor whose sign chooses the action")
    actions: list[Annotated[int, Field(ge=0, lt=MAX_ACTIONS)]] | None = Field(
        default=None, min_length=2, max_length=2, description="sign: [action where negative, action where >= 0]"
    )

    _shorthand = model_validator(mode="before")(_policy_shorthand)

    @model_validator(mode="after")
    def _fields(self) -> BehaviourSpec:
        _sign_fields(self)
        if self.kind == "sign" and self.epsilon <= 0.0:
            raise ValueError("a sign behaviour needs epsilon > 0, so that every action has a positive probability")
        if self.kind in OWN_VALUE_POLICIES and self.demon is None:
            raise ValueError(f"a {self.kind} behaviour names the control demon it acts on")
        if self.kind in ("uniform", "fixed") and self.demon is not None:
            raise ValueError(f"a {self.kind} behaviour needs no demon")
        if self.kind == "fixed":
            if self.probabilities is None or not math.isclose(sum(self.probabilities), 1.0, abs_tol=1e-9):
                raise ValueError("a fixed behaviour needs probabilities [up, down, left, right] summing to 1")
            if min(self.probabilities) <= 0.0:
                raise ValueError("a fixed behaviour must give every action a positive probability")
        return self
