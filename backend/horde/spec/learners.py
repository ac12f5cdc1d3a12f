"""The learners a demon may name: what the spec knows of each (its name, parameters and needs).

The registry is filled by the learner modules of the engine (`horde.core.learners`, one module per learner
family), each declaring its learners with `register(LearnerInfo(...))`; the spec validates a demon's learner,
its step-size mode and its `parameters` against it, the API schema lists the names, and the dashboard reads
the declarations from `GET /api/learners`. The spec imports nothing above it: the engine registers here when
`horde` is imported (`horde/__init__.py` imports `horde.core.learners` first).
"""

from __future__ import annotations

from dataclasses import dataclass

STEP_SIZES = ("constant", "autostep", "tidbd")
WHY_NOT_ADAPTIVE = (
    "Autostep and TIDBD are derived for TD(lambda) only (Mahmood, Sutton, Degris & Pilarski 2012 for supervised "
    "learning; Kearney, Veeriah, Travnik, Pilarski & Sutton 2019 for TD(lambda)); no paper defines their "
    "meta-gradient for the gradient-corrected, true online or emphatic learners"
)


@dataclass(frozen=True)
class Parameter:
    """A number a learner takes beyond alpha, alpha_w and lambda (a demon sets it in `parameters`)."""

    name: str
    default: float
    low: float  # inclusive bounds
    high: float
    text: str


@dataclass(frozen=True)
class LearnerInfo:
    """What the spec knows of a learner.

    Args:
        name: the name a demon writes (`learner = "..."`).
        text: one line for people choosing it (the dashboard's list, `GET /api/learners`).
        paper: where its equations come from.
        action_values: learns action values over state-action features (GQ): may follow its own greedy /
            softmax / epsilon-greedy target policy, and a behaviour may act on it.
        secondary: keeps a second weight vector learned at `alpha_w` (gradient corrections).
        step_sizes: the step-size modes with a published form for it ("constant", "autostep", "tidbd").
        traces: it has a published form with lambda > 0; False: lambda = 0 only (a demon's lambda > 0 is
            refused, and one that leaves lambda out learns with 0 whatever [learning] says: `demon_lambda`).
        parameters: its own numbers, with defaults and bounds.
    """

    name: str
    text: str
    paper: str = ""
    action_values: bool = False
    secondary: bool = False
    step_sizes: tuple[str, ...] = ("constant",)
    parameters: tuple[Parameter, ...] = ()
    traces: bool = True

    def parameter(self, name: str) -> Parameter | None:
        return next((p for p in self.parameters if p.name == name), None)


REGISTRY: dict[str, LearnerInfo] = {}


def register(info: LearnerInfo) -> LearnerInfo:
    """Declare a learner (its module in `horde.core.learners` does, once). Returns `info`."""
    if info.name in REGISTRY and REGISTRY[info.name] != info:
        raise ValueError(f"learner {info.name!r} is declared twice, differently")
    unknown = set(info.step_sizes) - set(STEP_SIZES)
    if "constant" not in info.step_sizes or unknown:
        raise ValueError(f"learner {info.name!r}: step sizes {info.step_sizes} must include 'constant' and be among "
                         f"{STEP_SIZES}")  # fmt: skip
    REGISTRY[info.name] = info
    return info


def learner_names() -> tuple[str, ...]:
    """Every declared learner, by name (so the order never depends on which module was imported first)."""
    return tuple(sorted(REGISTRY))


def learner_info(name: str) -> LearnerInfo:
    """The declaration of a learner.

    Raises:
        ValueError: an unknown name (the message lists the known ones).
    """
    info = REGISTRY.get(name)
    if info is None:
        known = ", ".join(learner_names()) or "none: horde.core.learners is not imported"
        raise ValueError(f"unknown learner {name!r} (known: {known})")
    return info


def step_size_problem(learner: str, step_size: str) -> str | None:
    """Why a learner x step-size combination is undefined, or None when a paper defines it."""
    if step_size in learner_info(learner).step_sizes:
        return None
    return f"step_size {step_size!r} is not defined for learner {learner!r}: {WHY_NOT_ADAPTIVE}"
