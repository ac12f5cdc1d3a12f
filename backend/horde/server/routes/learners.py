"""GET /api/learners: the learners a demon may name, each with its parameters and needs (the registry's)."""

from __future__ import annotations

from fastapi import APIRouter
from pydantic import BaseModel, Field

from horde.spec import learner_info, learner_names

router = APIRouter(prefix="/learners", tags=["learners"])


class ParameterOut(BaseModel):
    name: str
    default: float
    low: float
    high: float
    text: str


class LearnerOut(BaseModel):
    name: str = Field(description="what a demon writes: learner = NAME")
    text: str = Field(description="one line for people choosing it")
    paper: str
    action_values: bool = Field(description="learns action values: may follow its own greedy / softmax policy")
    secondary: bool = Field(description="keeps a second weight vector learned at alpha_w")
    traces: bool = Field(
        description="learns with eligibility traces (lambda > 0); false: lambda 0 only (a demon's lambda > 0 is a "
        "422, and one that leaves lambda out learns with 0 whatever [learning] says)"
    )
    step_sizes: list[str] = Field(description="the step-size modes it is defined for")
    parameters: list[ParameterOut] = Field(description="its own numbers, set in a demon's `parameters`")


@router.get("", summary="The learners a demon may name, with their parameters and needs")
def list_learners() -> list[LearnerOut]:
    """Declared by the engine's learner modules (`horde.core.learners`), in the order of their names."""
    out = []
    for name in learner_names():
        info = learner_info(name)
        parameters = [ParameterOut(name=p.name, default=p.default, low=p.low, high=p.high, text=p.text)
                      for p in info.parameters]  # fmt: skip
        out.append(
            LearnerOut(
                name=info.name,
                text=info.text,
                paper=info.paper,
                action_values=info.action_values,
                secondary=info.secondary,
                traces=info.traces,
                step_sizes=list(info.step_sizes),
                parameters=parameters,
            )
        )
    return out
