"""One task of a study on a world whose transitions are known (the chains, Baird's star: `horde.worlds.chains`).

The Gymnasium agent learns episode by episode (a whole episode in one call under a state-blind behaviour) and is
measured at the same checkpoints as a grid task (`task.run_task`), against every state's exact value
(`horde.worlds.state_values`):

- `error`: the RMS error over the non-terminal states, weighted as `measure.weighting` says: `on-policy` (the
  behaviour's distribution over states, the book's VE: figures 9.1-9.5, 11.5 and 11.6) or `uniform` (every
  state alike: the book's 19-state walk figures, 7.2 and 12.3-12.8);
- `scale`: the same norm of the exact values (what a relative error divides by; 0 on Baird's star, whose values
  are all 0: its relative error is then the error itself);
- `rmspbe`: the root-mean-square projected Bellman error, weighted by the behaviour's distribution;
- `rupee` and `prediction` (at the start state) as on the grid.
After training: `values` (every state's prediction), `exact`, `states`.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from horde.spec import RunSpec
from horde.studies.spec import MeasureSpec
from horde.worlds.gymnasium import GymAgent
from horde.worlds.state_values import demon_truth, model_of, predictions_at_states

TaskData = dict[str, object]


def run_model_task(spec: RunSpec, run: int, measure: MeasureSpec, marks: list[int]) -> TaskData:
    """Train the spec's Horde once on its known world and measure it at the checkpoints `marks` (episodes).

    Raises:
        ValueError: the world's transitions are not known, or a measured demon's question has no exact answer.
    """
    began, began_cpu = time.perf_counter(), time.process_time()
    agent = GymAgent(spec, np.random.default_rng([spec.seed, run]))
    horde = agent.horde
    chain = model_of(agent.spec)
    if chain is None:
        raise ValueError(f"a study on a Gymnasium world needs one whose transitions are known (the chains, Baird's "
                         f"star); {getattr(spec.world, 'id', '')!r} is not one")  # fmt: skip
    names = list(measure.demons) if measure.demons is not None else horde.prediction_demons()
    cache: dict[object, Any] = {}  # what the demons' questions share
    truths = {name: demon_truth(horde, name, chain, cache=cache) for name in names}
    missing = [name for name, truth in truths.items() if truth is None]
    if missing:
        raise ValueError(f"measure.demons: no exact answer for {', '.join(missing)} (a question reading predictions "
                         "or action values, or a policy over action values)")  # fmt: skip
    start = int(np.argmax(chain.start))
    demons: dict[str, dict[str, list[float]]] = {
        n: {"error": [], "scale": [], "rupee": [], "prediction": [], "rmspbe": []} for n in names
    }
    returns_out: list[float] = []
    values = np.zeros((len(chain.states), len(names)))
    for mark in marks:
        returns = []
        while agent.episode < mark:
            agent.run_episode()
            returns.append(float(agent.returns[1]))
        returns_out.append(float(np.mean(returns)) if returns else float("nan"))
        state = agent.learner.horde_state()
        with np.errstate(all="ignore"):
            values = predictions_at_states(horde, state, chain, names)  # [N, D]
        rupee = horde.rupee(state)
        for j, name in enumerate(names):
            truth, row = truths[name], demons[name]
            assert truth is not None
            row["error"].append(truth.error(values[:, j], measure.weighting))
            row["scale"].append(truth.scale(measure.weighting))
            row["rmspbe"].append(truth.rmspbe(values[:, j]) if np.isfinite(values[:, j]).all() else float("inf"))
            row["rupee"].append(float(rupee[horde.index[name]]))
            row["prediction"].append(float(values[start, j]))
    diverged = agent.learner.horde_state().diverged
    return {
        "episodes": marks,
        "truth": "exact",
        "returns": returns_out,
        "demons": demons,
        "states": chain.states.tolist(),
        "values": {name: values[:, j].tolist() for j, name in enumerate(names)},
        "exact": {name: truths[name].exact.tolist() for name in names},  # type: ignore[union-attr]
        "steps": agent.total_steps,
        "diverged": [name for name in names if diverged[horde.index[name]]],
        "seconds": time.perf_counter() - began,
        "cpu_seconds": time.process_time() - began_cpu,
    }
