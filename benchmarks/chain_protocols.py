"""Demons on a chain scenario's protocol: how far each ends from its TD fixed point, and what that takes (issue 25).

Each demon given (a JSON object merged over the scenario's first demon: its question, with another learner,
step sizes or features) learns through the scenario's protocol (its episodes, its seed) exactly as `horde run`
learns it (`GymAgent.run_episode`, all demons at once), then every state's value is compared with the demon's
TD fixed point (`horde.worlds.state_values`). It prints per demon the largest |value - fixed point| over the
states beside the issue's bar (0.05, or 5 % of the true values' range where that is larger) and the wall and
CPU seconds of the protocol. `--time-errors` times one `StateErrors.measure` (the RMSVE and RMSPBE a live run
records) and one protocol step of the same Horde, in alternated rounds.

Run: `python -m benchmarks.chain_protocols SCENARIO [--demon JSON ...] [--episodes N] [--seed S] [--time-errors]`,
e.g. `python -m benchmarks.chain_protocols boyan-chain --demon '{"name": "g1", "learner": "gtd1", "alpha": 0.5}'`.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from horde.scenarios import load_scenario
from horde.spec import RunSpec
from horde.worlds.gymnasium import GymAgent
from horde.worlds.state_values import demon_truth, model_of, predictions_at_states, state_errors

SCENARIOS = Path(__file__).resolve().parents[1] / "scenarios"


def spec_with(name: str, demons: list[dict[str, object]], episodes: int | None, seed: int | None) -> RunSpec:
    spec = load_scenario(SCENARIOS / f"{name}.toml")
    data = spec.model_dump(by_alias=True, exclude_none=True)
    if demons:
        first = data["demons"][0]
        data["demons"] = [{**first, **demon} for demon in demons]
    if episodes is not None:
        data["protocol"]["episodes"] = episodes
    if seed is not None:
        data["seed"] = seed
    return RunSpec.model_validate(data)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("scenario")
    parser.add_argument("--demon", action="append", default=[], help="JSON merged over the first demon")
    parser.add_argument("--episodes", type=int)
    parser.add_argument("--seed", type=int)
    parser.add_argument("--time-errors", action="store_true")
    args = parser.parse_args(argv)
    spec = spec_with(args.scenario, [json.loads(d) for d in args.demon], args.episodes, args.seed)
    agent = GymAgent(spec, np.random.default_rng([spec.seed, 0]))
    wall, cpu = time.perf_counter(), time.process_time()
    while agent.episode < spec.protocol.episodes:
        agent.run_episode()
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    chain = model_of(agent.spec)
    assert chain is not None, "not a chain scenario"
    names = agent.horde.names
    values = predictions_at_states(agent.horde, agent.learner.horde_state(), chain, names)
    print(f"{args.scenario}: {spec.protocol.episodes} episodes, {agent.total_steps} steps, {wall:.1f} s wall, "
          f"{cpu:.1f} s CPU (all demons together)")  # fmt: skip
    for j, name in enumerate(names):
        truth = demon_truth(agent.horde, name, chain)
        assert truth is not None
        bar = max(0.05, 0.05 * float(truth.exact.max() - truth.exact.min()))
        worst = float(np.abs(values[:, j] - truth.fixed_point).max())
        demon = agent.spec.demons[j]
        print(f"  {name:>16} {demon.learner:>6} alpha {demon.alpha} alpha_w {demon.alpha_w} {demon.step_size or ''}: "
              f"max |v - fixed point| {worst:.4f} (bar {bar:.3f}: {'within' if worst <= bar else 'OUTSIDE'}), "
              f"RMSVE {truth.rmsve(values[:, j]):.4f}")  # fmt: skip
    if args.time_errors:
        errors = state_errors(agent.horde)
        assert errors is not None
        measure, step = [], []
        for _ in range(20):  # alternated rounds
            began = time.thread_time()
            errors.measure(agent.learner.horde_state())
            measure.append(time.thread_time() - began)
            began = time.thread_time()
            steps = agent.run_episode()
            step.append((time.thread_time() - began) / max(1, steps))
        print(f"  StateErrors.measure: median {1e3 * float(np.median(measure)):.2f} ms CPU; an episode's step "
              f"{1e6 * float(np.median(step)):.1f} us CPU")  # fmt: skip
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
