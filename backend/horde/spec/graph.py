"""The demon graph: which demons read which (predictions, policies, conditions), and an order that respects it.

Demons that read other demons form a graph; a cycle is a 422 (DESIGN section 4). Each step runs in
dependency order, so that a prediction read by another demon is the one for s_{t+1} after its owner's update.
"""

from __future__ import annotations

import heapq

from horde.spec.demons import DemonSpec
from horde.spec.expressions import expr_predictions
from horde.spec.features import FeatureSpec


def demon_dependencies(demon: DemonSpec, default_features: FeatureSpec) -> set[str]:
    """Names of the demons whose predictions or policies this demon reads."""
    deps: set[str] = set()
    for expr in (demon.cumulant, demon.outcome, demon.continuation):
        deps |= expr_predictions(expr)
    if demon.policy.kind == "of" and demon.policy.demon:
        deps.add(demon.policy.demon)
    features = demon.features or default_features
    if features.condition:
        deps.add(features.condition.demon)
    return deps


def topological_order(deps: dict[str, set[str]]) -> list[str]:
    """Order names so that every name comes after the names it depends on.

    Iterative (Kahn's algorithm), so a chain of any length within the limits orders without recursion;
    ties are broken by name, so the order is the same for the same graph.

    Raises:
        ValueError: naming the demons of a cycle.
    """
    waiting = {name: len(deps[name]) for name in deps}  # dependencies not yet ordered
    readers: dict[str, list[str]] = {name: [] for name in deps}
    for name in deps:
        for dep in deps[name]:
            readers[dep].append(name)
    ready = sorted(name for name, count in waiting.items() if count == 0)
    heapq.heapify(ready)
    order: list[str] = []
    while ready:
        name = heapq.heappop(ready)
        order.append(name)
        for reader in readers[name]:
            waiting[reader] -= 1
            if waiting[reader] == 0:
                heapq.heappush(ready, reader)
    if len(order) < len(deps):
        raise ValueError(f"demons depend on each other in a cycle: {' -> '.join(_cycle(deps, set(order)))}")
    return order


def _cycle(deps: dict[str, set[str]], ordered: set[str]) -> list[str]:
    """One cycle among the names left unordered: follow unordered dependencies until a name repeats."""
    name = min(n for n in deps if n not in ordered)
    path: list[str] = []
    seen: dict[str, int] = {}
    while name not in seen:
        seen[name] = len(path)
        path.append(name)
        name = min(d for d in deps[name] if d not in ordered)
    return [*path[seen[name] :], name]
