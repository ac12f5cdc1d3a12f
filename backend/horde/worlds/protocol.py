"""The protocol on a Gymnasium world: learn, then compare every prediction with realised returns.

One trial: the agent learns for `protocol.episodes` episodes under the run's behaviour; then, with
learning off, it follows the behaviour on for a while and keeps `evaluation.states` test states spread
over that stretch (the environment's internal state and the sensors there). At each test state the
demon's prediction is read, and `evaluation.rollouts` rollouts follow the demon's own target policy from
that state in an unlimited copy of the environment (a question's answer does not stop at truncation),
each until its continuation has fallen below 1e-3, the environment terminates, or `evaluation.cap`
steps. The realised discounted return of a rollout is

    G = sum_t (prod_{j < t} gamma_{j+1}) (r_{t+1} + (1 - gamma_{t+1}) z_{t+1}),

with r, z and gamma the demon's cumulant, outcome and continuation (times discount) evaluated on the
sensors after each step, gamma = 0 where the environment terminates. A demon's row compares the mean
prediction over the test states with the mean realised return over the same states (with its Monte-Carlo
standard error over the rollouts), and gives the root-mean-square error over the test states too.

Questions whose expressions read other demons' predictions have no Monte-Carlo truth here (their rows
say so).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from horde.core.questions import Program
from horde.spec import RunSpec, expr_predictions
from horde.worlds.gymnasium import GymAgent, GymWorld, policy_probs
from horde.worlds.state_values import values_report

Progress = Callable[[int, int], None]
CONTINUATION_FLOOR = 1e-3  # a rollout ends once the product of continuations falls below this


@dataclass
class GymDemonResult:
    name: str
    prediction: float  # mean over the test states
    truth: float | None  # mean realised return over the test states
    truth_stderr: float | None  # Monte-Carlo standard error of `truth` (over the rollouts)
    error: float | None  # prediction - truth
    rmse: float | None  # over the test states
    scale: float | None  # RMS of the realised returns: the error's yardstick for questions whose mean is near 0
    diverged: bool = False  # frozen by the engine (its weights set to 0): not compared with the returns
    values: dict[str, object] | None = None  # a world with known transitions: every state's value and truth

    @property
    def relative(self) -> float | None:
        """|error| / max(|truth|, RMS of the returns) (see the README: which questions must be within 10 %)."""
        if self.error is None or self.truth is None or self.scale is None:
            return None
        denominator = max(abs(self.truth), self.scale)
        return abs(self.error) / denominator if denominator > 0 else None

    def as_dict(self) -> dict[str, object]:
        return {"name": self.name, "prediction": self.prediction, "truth": self.truth,
                "truth_stderr": self.truth_stderr, "error": self.error, "rmse": self.rmse, "scale": self.scale,
                "relative_error": self.relative, "diverged": self.diverged, **(self.values or {})}  # fmt: skip


@dataclass
class GymProtocolResult:
    demons: list[GymDemonResult]
    seconds: float
    steps: int
    states: int
    rollouts: int
    cap: int


def _returns(r: np.ndarray, z: np.ndarray, gamma: np.ndarray) -> np.ndarray:
    """[D] realised returns of T steps: r, z, gamma [T, D] after each step."""
    weight = np.vstack([np.ones((1, r.shape[1])), np.cumprod(gamma, axis=0)[:-1]])  # [T, D] prod_{j<t} gamma_{j+1}
    return (weight * (r + (1.0 - gamma) * z)).sum(axis=0)


def rollout_returns(spec: RunSpec, world: GymWorld, state: np.ndarray, sensors: np.ndarray, demons: list[int],
                    rollouts: int, cap: int, rng: np.random.Generator) -> tuple[np.ndarray, int]:  # fmt: skip
    """[rollouts, len(demons)] realised returns of the demons (who share one target policy) from a state, and
    how many rollouts were still running at the cap."""
    specs = [spec.demons[i] for i in demons]
    names = world.sensor_names
    index = {n: i for i, n in enumerate(names)}
    program = Program([d.cumulant for d in specs] + [d.outcome for d in specs] + [d.continuation for d in specs],
                      index, {})  # fmt: skip
    discount = np.array([d.discount for d in specs])  # [Dp]
    policy = specs[0].policy
    out = np.empty((rollouts, len(specs)))
    capped = 0
    for k in range(rollouts):
        world.set_state(state, sensors)
        current = sensors
        trajectory, ends = [], []
        product = 1.0
        for _ in range(cap):
            probs = policy_probs(policy, current, names, world.num_actions)
            action = min(int(np.searchsorted(np.cumsum(probs), rng.random(), side="right")), len(probs) - 1)
            current, terminated, _ = world.step(action)
            trajectory.append(current)
            ends.append(terminated)
            if terminated:
                break
            values = program.evaluate(current[None])[0]
            product *= float(np.max(np.clip(values[2 * len(specs) :], 0.0, 1.0) * discount))
            if product < CONTINUATION_FLOOR:
                break
        else:
            capped += 1
        values = program.evaluate(np.array(trajectory))  # [T, 3 Dp]
        d = len(specs)
        gamma = np.clip(values[:, 2 * d :], 0.0, 1.0) * discount  # [T, Dp]
        gamma[np.array(ends)] = 0.0
        out[k] = _returns(values[:, :d], values[:, d : 2 * d], gamma)
    return out, capped


def _test_states(agent: GymAgent, count: int, spacing: int = 25) -> list[tuple[np.ndarray, np.ndarray]]:
    """`count` test states (the environment's state and the sensors there), one every `spacing` steps of the
    behaviour going on (learning off)."""
    states: list[tuple[np.ndarray, np.ndarray]] = []
    while len(states) < count:
        agent.step()
        if agent.total_steps % spacing == 0:
            states.append((agent.world.get_state(), agent.sensors.copy()))
    return states


def run_gym_protocol(spec: RunSpec, progress: Progress | None = None) -> GymProtocolResult:
    """Learn for `protocol.episodes` episodes, then compare predictions with realised returns (see the module)."""
    began = time.perf_counter()
    agent = GymAgent(spec, np.random.default_rng([spec.seed, 0]))
    spec, protocol, evaluation = agent.spec, spec.protocol, spec.protocol.evaluation  # its sensors resolved
    while agent.episode < protocol.episodes:
        agent.run_episode()
        if progress is not None:
            progress(agent.episode, protocol.episodes + evaluation.states)
    # Test states: the behaviour goes on without learning; one state every `spacing` steps.
    agent.learner.set_learning(np.zeros(agent.horde.num_demons, dtype=bool))
    wanted = evaluation.demons or agent.horde.prediction_demons()
    every_state = values_report(agent.horde, agent.learner.horde_state(), wanted)
    states = _test_states(agent, evaluation.states)
    index = [agent.horde.index[name] for name in wanted]
    predictions = np.empty((len(states), len(index)))
    for s, (_, sensors) in enumerate(states):
        agent.learner.observe(sensors)
        predictions[s] = agent.learner.prediction()[index]
    groups: dict[str, list[int]] = {}
    for j, i in enumerate(index):
        demon = spec.demons[i]
        if any(expr_predictions(e) for e in (demon.cumulant, demon.outcome, demon.continuation)):
            continue
        groups.setdefault(demon.policy.model_dump_json(), []).append(j)
    truths = np.full((len(states), len(index)), np.nan)  # [N, D] mean realised return at each test state
    variances = np.zeros((len(states), len(index)))  # [N, D] the Monte-Carlo variance of each of those means
    world = GymWorld(agent.world.spec, time_limit=False)
    world.reset(seed=spec.seed)
    rng = np.random.default_rng([spec.seed, 1])
    for s, (state, sensors) in enumerate(states):
        for members in groups.values():
            returns, _ = rollout_returns(spec, world, state, sensors, [index[j] for j in members], evaluation.rollouts,
                                      evaluation.cap, rng)  # fmt: skip
            truths[s, members] = returns.mean(axis=0)
            if len(returns) > 1:
                variances[s, members] = returns.var(axis=0, ddof=1) / len(returns)
        if progress is not None:
            progress(protocol.episodes + s + 1, protocol.episodes + evaluation.states)
    world.close()
    rows = []
    diverged = agent.learner.readout().diverged  # [D]
    for j, name in enumerate(wanted):
        prediction = float(predictions[:, j].mean())
        if diverged[index[j]] or np.isnan(truths[:, j]).any():  # diverged: frozen at 0 weights, nothing to compare
            rows.append(GymDemonResult(name, prediction, None, None, None, None, None, bool(diverged[index[j]]),
                                       every_state.get(name)))  # fmt: skip
            continue
        truth = float(truths[:, j].mean())
        stderr = float(math.sqrt(variances[:, j].sum()) / len(states))
        rmse = float(np.sqrt(np.mean((predictions[:, j] - truths[:, j]) ** 2)))
        scale = float(np.sqrt(np.mean(truths[:, j] ** 2)))
        rows.append(GymDemonResult(name, prediction, truth, stderr, prediction - truth, rmse, scale, False,
                                   every_state.get(name)))  # fmt: skip
    return GymProtocolResult(rows, time.perf_counter() - began, agent.total_steps, len(states), evaluation.rollouts,
                             evaluation.cap)  # fmt: skip


def format_gym_results(spec: RunSpec, result: GymProtocolResult) -> str:
    """`horde run`'s table for a Gymnasium world: prediction beside the realised return, per demon."""
    header = ("demon", "prediction", "realised return", "± stderr", "error", "rel. error %", "RMSE")

    def number(value: float | None, digits: int = 3) -> str:
        return "-" if value is None or not math.isfinite(value) else f"{value:.{digits}f}"

    def percent(value: float | None) -> str:
        return number(None if value is None else 100 * value, 1)

    rows = [(d.name, "diverged" if d.diverged else number(d.prediction), number(d.truth), number(d.truth_stderr),
             number(d.error), percent(d.relative), number(d.rmse)) for d in result.demons]  # fmt: skip
    widths = [max(len(r[i]) for r in [header, *rows]) for i in range(len(header))]
    lines = ["  ".join(cell.rjust(w) if i else cell.ljust(w) for i, (cell, w) in enumerate(zip(r, widths, strict=True)))
             for r in [header, *rows]]  # fmt: skip
    lines.insert(1, "  ".join("-" * w for w in widths))
    judged = [d for d in result.demons if d.error is not None and d.truth is not None]
    relative = [d.name for d in judged if d.relative is not None and d.relative <= 0.10]
    absolute = [d.name for d in judged if abs(d.error or 0.0) <= max(0.05, 0.05 * abs(d.truth or 0.0))]
    lines.append("")
    lines.append(f"within 10 % (rel. error): {len(relative)} of {len(judged)} demons; "
                 f"within 0.05 or 5 % of the realised return: {len(absolute)} of {len(judged)}")  # fmt: skip
    lines.append(
        f"{spec.protocol.episodes} episodes of {spec.world.kind} {getattr(spec.world, 'id', '')}, {result.steps} steps "
        f"in {result.seconds:.1f} s; means over {result.states} test states, {result.rollouts} rollouts of each "
        f"demon's target policy per state (until its continuation < {CONTINUATION_FLOOR:g}, capped at {result.cap}); "
        "rel. error = |error| / max(|realised|, RMS of the realised returns)"
    )
    return "\n".join(lines)
