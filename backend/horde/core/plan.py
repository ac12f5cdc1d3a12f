"""A run spec resolved, once, into a plan: everything the engine lays its blocks out from, as plain data.

Every demon's learner (and the engine's kernel for it), step sizes (its own or the run's defaults, and what
its learner makes of them: tdrc's h learns at eta alpha), lambda, step-size mode, features, the demons it
reads, its stage (a prediction read by another demon is the one for s_{t+1} after its owner's update, so a
reader is in a later stage); the world's sensors with their bounds, its actions; the behaviour. `Horde`
compiles from the plan alone: nothing reads the spec's helpers while it compiles.
"""

from __future__ import annotations

from dataclasses import dataclass

from horde.core.learners import Kernel, kernel_for
from horde.spec import (
    BehaviourSpec,
    DemonSpec,
    Expr,
    FeatureSpec,
    PolicySpec,
    RunSpec,
    WorldSpec,
    check_demon_graph,
    demon_dependencies,
    demon_lambda,
    demon_step_size,
    learner_info,
)


@dataclass(frozen=True)
class DemonPlan:
    """One demon, resolved."""

    name: str
    learner: str
    kernel: Kernel
    action_values: bool  # learns action values over state-action features
    lam: float
    alpha: float  # before the division by the active count
    alpha_w: float  # of the secondary weights (tdrc: of h)
    beta: float  # tdrc's regulariser (0 elsewhere)
    step_size: str
    meta: float  # autostep's mu, tidbd's theta
    features: FeatureSpec
    feature_key: str  # equal for demons over the same features
    dependencies: frozenset[str]
    stage: int
    policy: PolicySpec
    cumulant: Expr
    outcome: Expr
    continuation: Expr
    discount: float
    reset: bool
    initial_weights: tuple[float, ...] | None


@dataclass(frozen=True)
class Plan:
    """A run, resolved (see the module)."""

    demons: tuple[DemonPlan, ...]
    order: tuple[str, ...]  # dependency order
    sensors: tuple[str, ...]
    bounds: dict[str, tuple[float, float]]
    num_actions: int
    plane: tuple[float, float]  # the grid world's width and height (positions are scaled by them); 1, 1 elsewhere
    grid: WorldSpec | None
    behaviour: BehaviourSpec
    autostep_tau: float
    dtype: str  # "float64" or "float32": of the weights, traces and per-weight vectors (`[learning] dtype`)


def _demon(spec: RunSpec, demon: DemonSpec, stage: int, dependencies: set[str], keys: dict[str, str]) -> DemonPlan:
    learning = spec.learning
    features = demon.features or spec.features
    key = keys.setdefault(features.model_dump_json(), features.model_dump_json())
    mode, meta = demon_step_size(demon, learning)
    kernel = kernel_for(demon.learner, mode)
    given = {p.name: demon.parameter(p.name) for p in learner_info(demon.learner).parameters}
    alpha = demon.alpha if demon.alpha is not None else learning.alpha
    alpha_w = demon.alpha_w if demon.alpha_w is not None else learning.alpha_w
    alpha, alpha_w, beta = kernel.rates(alpha, alpha_w, given)
    return DemonPlan(
        name=demon.name,
        learner=demon.learner,
        kernel=kernel,
        action_values=demon.action_values,
        lam=demon_lambda(demon, learning),
        alpha=float(alpha),
        alpha_w=float(alpha_w),
        beta=float(beta),
        step_size=mode,
        meta=float(meta),
        features=features,
        feature_key=key,
        dependencies=frozenset(dependencies),
        stage=stage,
        policy=demon.policy,
        cumulant=demon.cumulant,
        outcome=demon.outcome,
        continuation=demon.continuation,
        discount=float(demon.discount),
        reset=demon.reset == "episode",
        initial_weights=tuple(demon.initial_weights) if demon.initial_weights is not None else None,
    )


def resolve(spec: RunSpec) -> Plan:
    """The plan of a validated spec (a Gymnasium world's sensors resolved: `horde.worlds.gym_spaces`).

    Raises:
        UnresolvedWorldError: a Gymnasium world whose sensors were not resolved.
    """
    order = check_demon_graph(spec)
    deps = {d.name: demon_dependencies(d, spec.features) for d in spec.demons}
    stage: dict[str, int] = {}
    for name in order:
        stage[name] = 1 + max((stage[d] for d in deps[name]), default=-1)
    keys: dict[str, str] = {}
    world = spec.world
    grid = world if isinstance(world, WorldSpec) else None
    return Plan(
        demons=tuple(_demon(spec, d, stage[d.name], deps[d.name], keys) for d in spec.demons),
        order=tuple(order),
        sensors=tuple(world.sensor_names()),
        bounds=world.sensor_bounds(),
        num_actions=world.num_actions(),
        plane=(grid.width, grid.height) if grid is not None else (1.0, 1.0),
        grid=grid,
        behaviour=spec.behaviour,
        autostep_tau=float(spec.learning.autostep_tau),
        dtype=spec.learning.dtype,
    )
