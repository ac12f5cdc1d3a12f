"""The Horde-scale workloads of `horde bench`, written as run specs: nexting, off-policy and control.

Every workload is a `RunSpec` run by `Simulation`, the path a user's run takes: the world, features,
questions and policies of `scenarios/nexting.toml` (57 sensors tiled into 6065 features, 457 active),
with the demons below in place of the scenario's, under a uniform random behaviour, without RUPEE / UDE
(as protocols run).

* nexting: D TD(lambda) or GTD(lambda) demons (or true online TD, ETD, TD with Autostep / TIDBD: learner
  "td+autostep") on-policy, "what will sensor s read, scaled by c,
  discounted at gamma" over the 57 sensors, five timescales (gamma 0, 0.5, 0.75, 0.875, 0.9375) and as
  many scales c as D needs: the demons of a timescale share one trace.
* off_policy: D GTD(lambda) demons about 300 fixed target policies (drawn at random, seeded), each
  policy with one timescale: the demons of a policy share its trace (300 trace classes).
* control: D GQ(lambda) demons over 4 x 6065 state-action features, each with a softmax target policy
  over its own action values (rho of its own: a trace class per demon).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from horde.scenarios import load_scenario, scenario_dir
from horde.spec import RunSpec

TIMESCALES = (0.0, 0.5, 0.75, 0.875, 0.9375)  # the nexting robot's gammas
POLICIES = 300
LAMBDA = 0.9


def base() -> RunSpec:
    return load_scenario(scenario_dir() / "nexting.toml")


def sensors() -> list[str]:
    """The 57 tiled sensors of the nexting scenario."""
    return [t.sensor for t in base().features.sensors or []]


def _demons(name: str, demons: int, learner: str, seed: int) -> list[dict[str, Any]]:
    """The workload's demons; learner "td+autostep" means learner "td" with step_size "autostep"."""
    learner, _, step_size = learner.partition("+")
    names = sensors()
    rng = np.random.default_rng(seed)
    out: list[dict[str, Any]] = []
    if name == "nexting":
        for i in range(demons):
            sensor, rest = names[i % len(names)], i // len(names)
            gamma, scale = TIMESCALES[rest % len(TIMESCALES)], 1 + rest // len(TIMESCALES)
            out.append({
                "name": f"d{i}", "learner": learner, "policy": "uniform", "discount": gamma,
                "cumulant": {"mul": [{"sensor": sensor}, scale]},
            })  # fmt: skip
    elif name == "off_policy":
        policies = rng.dirichlet(np.ones(4), POLICIES)
        for i in range(demons):
            p = i % POLICIES
            out.append({
                "name": f"d{i}", "learner": learner, "discount": TIMESCALES[p % len(TIMESCALES)],
                "policy": {"kind": "fixed", "probabilities": (policies[p] / policies[p].sum()).tolist()},
                "cumulant": {"sensor": names[(i // POLICIES) % len(names)]},
            })  # fmt: skip
    elif name == "control":
        for i in range(demons):
            out.append({
                "name": f"d{i}", "learner": "gq", "discount": TIMESCALES[i % len(TIMESCALES)],
                "policy": {"kind": "softmax", "temperature": 1.0},
                "cumulant": {"sensor": names[i % len(names)]},
            })  # fmt: skip
    else:
        raise ValueError(f"unknown workload {name!r}")
    if step_size:
        out = [{**demon, "step_size": step_size} for demon in out]
    return out


def spec(name: str, demons: int, learner: str, seed: int = 0) -> RunSpec:
    """The run spec of a workload of `demons` demons."""
    data = base().model_dump(by_alias=True)
    data.update(
        demons=_demons(name, demons, learner, seed),
        behaviour={"kind": "uniform"},
        learning={"lambda": LAMBDA, "alpha": 0.1, "alpha_w": 0.001},
        seed=seed,
    )
    return RunSpec.model_validate(data)


def subset(spec_: RunSpec, count: int) -> tuple[RunSpec, np.ndarray]:
    """The spec with `count` of its demons spread evenly (for the reference), and their indices."""
    picked = np.unique(np.linspace(0, len(spec_.demons) - 1, min(count, len(spec_.demons))).astype(np.int64))
    data = spec_.model_dump(by_alias=True)
    data["demons"] = [data["demons"][i] for i in picked]
    return RunSpec.model_validate(data), picked
