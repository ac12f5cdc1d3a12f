"""The chain worlds (horde.worlds.chains): their environments against the book's numbers, and what must hold of
every shipped chain scenario (issue 25, 1): after its protocol every state's prediction is within 0.05 (or 5 %
of the value range) of the TD fixed point, and of the exact values where the features are tabular.

The fixed points and exact values here are computed independently of the engine and of
`horde.worlds.state_values`: the chains' transition matrices written out by hand, the features written from
the scenario's own numbers (tables, the Fourier cosines), and the linear solve of A w = b.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
from pydantic import ValidationError

from horde.cli import main
from horde.scenarios import load_scenario
from horde.spec import RunSpec
from horde.worlds.chains import register
from horde.worlds.gym_spaces import resolve_world

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
CHAIN_SCENARIOS = ("random-walk-5", "random-walk-19", "random-walk-1000", "boyan-chain")


def walk(n: int, jump: int, left: float, right: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """P [n, n] among states 1..n, r [n] expected reward, start [n], of the random walk (written out)."""
    P, r = np.zeros((n, n)), np.zeros(n)
    for s in range(1, n + 1):
        for step in [*range(-jump, 0), *range(1, jump + 1)]:
            t = s + step
            if t < 1:
                r[s - 1] += left / (2 * jump)
            elif t > n:
                r[s - 1] += right / (2 * jump)
            else:
                P[s - 1, t - 1] += 1 / (2 * jump)
    start = np.zeros(n)
    start[(n + 1) // 2 - 1] = 1.0
    return P, r, start


def boyan() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """States in the order 12, 11, ..., 1."""
    P, r = np.zeros((12, 12)), np.zeros(12)
    at = {s: 12 - s for s in range(1, 13)}
    for s in range(2, 13):
        r[at[s]] = -3.0
        for t in (s - 1, s - 2):
            if t >= 1:
                P[at[s], at[t]] += 0.5
    r[at[1]] = -2.0
    start = np.zeros(12)
    start[0] = 1.0
    return P, r, start


def model_of(name: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[int]]:
    if name == "boyan-chain":
        return (*boyan(), list(range(12, 0, -1)))
    n, jump, left = {"random-walk-5": (5, 1, 0.0), "random-walk-19": (19, 1, -1.0),
                     "random-walk-1000": (1000, 100, -1.0)}[name]  # fmt: skip
    return (*walk(n, jump, left, 1.0), list(range(1, n + 1)))


def features(spec: RunSpec, demon: int, states: list[int]) -> np.ndarray:
    """[N, n] the demon's features at every state, from the scenario's numbers."""
    f = spec.demons[demon].features or spec.features
    if f.kind == "table":
        table = f.table or []
        n = 1 + max(i for row in table for i in row)
        X = np.zeros((len(states), n))
        for j, s in enumerate(states):
            for k, i in enumerate(table[s]):
                X[j, i] += f.values[s][k] if f.values is not None else 1.0
        return X
    assert f.kind in ("fourier", "polynomial") and f.sensors is not None
    low, high = f.sensors[0].low, f.sensors[0].high
    u = (np.array(states, dtype=float) - low) / (high - low)
    if f.kind == "polynomial":  # 1, u, u^2, ..., u^order
        return u[:, None] ** np.arange((f.order or 0) + 1)
    return np.cos(np.pi * np.outer(u, np.arange((f.order or 0) + 1)))


def fixed_point(P: np.ndarray, r: np.ndarray, start: np.ndarray, X: np.ndarray, lam: float) -> np.ndarray:
    """The on-policy TD(lambda) fixed point's values X w, w solving X^T D (I - lam P)^-1 ((I - P) X w - r) = 0."""
    n = len(r)
    d = np.linalg.solve((np.eye(n) - P).T, start)
    d /= d.sum()
    trace = np.linalg.inv(np.eye(n) - lam * P)
    A = X.T @ (d[:, None] * (trace @ (np.eye(n) - P) @ X))
    b = X.T @ (d * (trace @ r))
    return X @ np.linalg.solve(A, b)


def test_the_exact_values_are_the_books() -> None:
    for name, truth in [("random-walk-5", lambda s: s / 6), ("random-walk-19", lambda s: (s - 10) / 10),
                        ("boyan-chain", lambda s: -2.0 * s)]:  # fmt: skip
        P, r, _, states = model_of(name)
        exact = np.linalg.solve(np.eye(len(r)) - P, r)
        assert exact == pytest.approx([truth(s) for s in states], abs=1e-9)
    P, r, _, _ = model_of("random-walk-1000")
    v = np.zeros(1000)
    for _ in range(3000):  # dynamic programming (the book's iterative policy evaluation), against the solve
        v = r + P @ v
    assert np.linalg.solve(np.eye(1000) - P, r) == pytest.approx(v, abs=1e-6)
    assert -0.95 < v[0] < -0.85 and v[499] == pytest.approx(-v[500], abs=1e-9)


@pytest.mark.parametrize("env_id, first, mean_return", [("horde/RandomWalk19-v0", 10, 0.0),
                                                         ("horde/BoyanChain-v0", 12, -24.0)])  # fmt: skip
def test_the_environments_step_as_their_models(env_id: str, first: int, mean_return: float) -> None:
    register()
    env = gym.make(env_id)
    returns, seen = [], set()
    obs, _ = env.reset(seed=3)
    assert obs == first
    for _ in range(2000):
        total, done = 0.0, False
        obs, _ = env.reset()
        while not done:
            obs, reward, done, _, _ = env.step(0)
            seen.add(int(obs))
            total += float(reward)
        returns.append(total)
    assert np.mean(returns) == pytest.approx(mean_return, abs=4 * np.std(returns) / math.sqrt(len(returns)) + 1e-9)
    assert 0 in seen and env.observation_space.n == (21 if "Walk" in env_id else 13)
    env.close()


@pytest.mark.slow
@pytest.mark.parametrize("name", CHAIN_SCENARIOS)
def test_every_chain_scenario_ends_at_its_td_fixed_point(name: str, tmp_path: Path) -> None:
    """`horde run --json` on the scenario: every state's value within 0.05 (or 5 % of the value range) of the TD
    fixed point; tabular features also of the exact values; and the json's own exact values are these."""
    out = tmp_path / "run.json"
    assert main(["run", str(SCENARIOS / f"{name}.toml"), "--json", str(out)]) == 0
    rows = {row["name"]: row for row in json.loads(out.read_text())}
    spec = load_scenario(SCENARIOS / f"{name}.toml")
    P, r, start, states = model_of(name)
    exact = np.linalg.solve(np.eye(len(r)) - P, r)
    tolerance = max(0.05, 0.05 * float(exact.max() - exact.min()))
    for i, demon in enumerate(spec.demons):
        row = rows[demon.name]
        assert row["states"] == states and row["exact"] == pytest.approx(exact, abs=1e-9)
        X = features(spec, i, states)
        lam = demon.lambda_ if demon.lambda_ is not None else spec.learning.lambda_
        best = fixed_point(P, r, start, X, lam)
        assert row["fixed_point"] == pytest.approx(best, abs=1e-6), demon.name
        values = np.array(row["values"])
        assert np.abs(values - best).max() <= tolerance, (demon.name, np.abs(values - best).max())
        if np.linalg.matrix_rank(X) == len(states):  # features that represent any values: the fixed point is exact
            assert np.abs(values - exact).max() <= tolerance, demon.name


def test_a_state_count_past_its_bound_or_on_a_fixed_chain_is_refused_naming_the_field() -> None:
    base = load_scenario(SCENARIOS / "random-walk-19.toml").model_dump(by_alias=True)
    with pytest.raises(ValidationError) as caught:
        RunSpec.model_validate({**base, "world": {**base["world"], "states": 5000}})
    assert caught.value.errors()[0]["loc"] == ("world", "states")
    boyan_data = load_scenario(SCENARIOS / "boyan-chain.toml").model_dump(by_alias=True)
    fixed = RunSpec.model_validate({**boyan_data, "world": {**boyan_data["world"], "states": 7}})
    with pytest.raises(ValidationError) as caught:
        resolve_world(fixed)
    assert caught.value.errors()[0]["loc"] == ("world", "states") and "fixed number" in str(caught.value)
    seven = RunSpec.model_validate({**base, "world": {**base["world"], "states": 7}, "features": {
        "kind": "table", "sensor": "state", "table": [[i] for i in range(9)]}})  # fmt: skip
    assert resolve_world(seven).world.sensor_bounds()["state"] == (0.0, 8.0)
    short = RunSpec.model_validate({**base, "world": {**base["world"], "states": 30}})  # 21 table rows, 32 readings
    with pytest.raises(ValidationError) as caught:
        resolve_world(short)
    assert caught.value.errors()[0]["loc"] == ("features", "table")


@pytest.mark.parametrize(("scenario", "episodes"), [("boyan-chain", 30), ("mountaincar-nexting", 4)])
def test_an_episode_learned_in_one_call_equals_it_learned_step_by_step(scenario: str, episodes: int) -> None:
    """boyan-chain's behaviour is uniform; MountainCar's a sign rule on the velocity, drawn at each state of the
    episode before any of it is learned (its demons TD and GTD, the latter owing its update across steps)."""
    from horde.worlds.gymnasium import GymAgent

    spec = load_scenario(SCENARIOS / f"{scenario}.toml")
    batched, stepped = GymAgent(spec, np.random.default_rng(5)), GymAgent(spec, np.random.default_rng(5))
    for _ in range(episodes):
        batched.run_episode()
    while stepped.episode < episodes:
        stepped.step()
    assert batched.total_steps == stepped.total_steps and batched.returns.tolist() == stepped.returns.tolist()
    for theta, other in zip(batched.learner.horde_state().theta, stepped.learner.horde_state().theta, strict=True):
        assert np.abs(theta).max() > 1.0 and theta == pytest.approx(other, abs=1e-12)


@pytest.mark.parametrize("lam", [0.0, 0.9])
def test_rmspbe_is_the_d_norm_of_the_projected_lambda_return_error(lam: float) -> None:
    """The 1000-state walk's aggregation demon (ten groups of 100 states: a projection that loses something):
    RMSPBE(v) = sqrt(sum_s d_s ((Pi delta)_s)^2), Pi = X (X' D X)^-1 X' D the projection onto the features under d
    and delta = (I - lambda M)^-1 (r - (I - M) v), each solved here from the matrices; 0 at the TD fixed point
    and at the true values; the same at lambda 0, where no inverse is kept."""
    from horde.core.horde import Horde
    from horde.worlds.state_values import demon_truth

    data = load_scenario(SCENARIOS / "random-walk-1000.toml").model_dump(by_alias=True)
    data["learning"]["lambda"] = lam
    data["demons"] = [{**demon, "lambda": lam} for demon in data["demons"]]
    truth = demon_truth(Horde(resolve_world(RunSpec.model_validate(data))), "aggregation")
    assert truth is not None and (truth.trace is None) == (lam == 0.0)
    n, X, d = len(truth.states), truth.features, truth.distribution
    projection = X @ np.linalg.pinv(X.T @ (d[:, None] * X)) @ X.T @ np.diag(d)  # [N, N]
    for values in (np.linspace(-1.0, 1.0, n), np.random.default_rng(3).normal(size=n), X @ np.ones(X.shape[1])):
        delta = np.linalg.solve(np.eye(n) - lam * truth.M, truth.r - (np.eye(n) - truth.M) @ values)
        expected = math.sqrt(float(d @ (projection @ delta) ** 2))
        assert expected > 1e-3 and truth.rmspbe(values) == pytest.approx(expected, rel=1e-9)
    assert truth.rmspbe(truth.fixed_point) < 1e-9 and truth.rmspbe(truth.exact) < 1e-9
