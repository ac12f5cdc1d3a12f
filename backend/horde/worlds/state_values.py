"""Every state's value on a world whose transitions are known (`horde.worlds.chains.Model`): the truth, the
TD fixed point, and the errors the books plot.

For a demon whose question reads only sensors (its cumulant c, outcome z and continuation times discount
gamma, gamma = 0 where the world terminates) and whose target policy pi is given (uniform, fixed or a sign
rule), the model gives, over the N non-terminal states,

    M[s, s'] = sum over transitions s -> s' of pi(a|s) p gamma,   r[s] = sum of pi(a|s) p (c + (1 - gamma) z),

so the exact values are v = (I - M)^-1 r (a linear solve: N = 1000 for the 1000-state walk, a dense solve of
about 0.05 s, the values dynamic programming converges to). With the demon's features X [N, n], its lambda
and the behaviour's distribution over states d (D = diag(d): the expected visits of an episode under the
behaviour, normalised, the on-policy distribution mu of Sutton & Barto 2018 (9.2) when behaviour and target
agree; the stationary distribution of a world that never ends), the TD(lambda) fixed point solves
A w = b with

    A = X^T D (I - lambda M)^-1 (I - M) X,   b = X^T D (I - lambda M)^-1 r

(off-policy, the fixed point of importance-sampled TD(lambda), GTD(lambda), TDC and TDRC: Maei 2011), by
least squares where A is singular (Baird's eight features over seven states). The errors of values v = X w:

* RMSVE: sqrt(sum_s d_s (v_s - v_pi,s)^2), weighted by d (the book's VE, figures 9.1-9.5, 11.5);
* RMS error: sqrt(mean_s (v_s - v_pi,s)^2), every state alike (the book's chapters 7 and 12, the 19-state walk);
* RMSPBE: sqrt(g^T C^+ g), g = X^T D (I - lambda M)^-1 (r - (I - M) v), C = X^T D X: the projected Bellman
  error with the same lambda and weighting (0 at the TD fixed point; Sutton et al. 2009 for lambda = 0).

`StateErrors` is what a live run records as it goes (`horde.runs.recorder`): RMSVE and RMSPBE of every demon
that has a truth, from its weights at that moment, with everything that does not change with the weights
computed once (the RMSPBE's g = g0 - G v, G = X^T D (I - lambda M)^-1 (I - M) [n, N], and C^+), so that one
measurement costs a forward pass over the N states and O(n N) per demon.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from horde.core.horde import Horde, HordeState
from horde.core.questions import Program
from horde.spec import BehaviourSpec, GymnasiumWorldSpec, PolicySpec, RunSpec, expr_predictions
from horde.worlds.baird import BAIRD_ID
from horde.worlds.chains import CHAINS, Model, model
from horde.worlds.gymnasium import policy_probs

WEIGHTINGS = ("on-policy", "uniform")


def has_model(spec: RunSpec) -> bool:
    """Whether the spec's world has discrete states with known transitions (`model_of` is not None), without
    building the model."""
    world = spec.world
    return isinstance(world, GymnasiumWorldSpec) and (world.id == BAIRD_ID or world.id in CHAINS)


def model_of(spec: RunSpec) -> Model | None:
    """The transitions of the spec's world, where they are known (the chains, Baird's star); else None."""
    world = spec.world
    if not isinstance(world, GymnasiumWorldSpec):
        return None
    return model(world.id, world.states)


def _rows(spec: RunSpec, obs: np.ndarray, reward: np.ndarray, terminated: np.ndarray) -> np.ndarray:
    """[K, S] the sensors: state, reward, terminated, truncated (0)."""
    names = spec.world.sensor_names()
    rows = np.zeros((len(obs), len(names)))
    for name, column in (("state", obs), ("reward", reward), ("terminated", terminated)):
        rows[:, names.index(name)] = column
    return rows


def state_sensors(spec: RunSpec, chain: Model) -> np.ndarray:
    """[N, S] the sensors at each non-terminal state, as at an episode's first state (reward 0)."""
    zeros = np.zeros(len(chain.states))
    return _rows(spec, chain.states.astype(float), zeros, zeros)


def _probs(policy: PolicySpec | BehaviourSpec, spec: RunSpec, chain: Model) -> np.ndarray | None:
    """[N, A] a given policy's probabilities at every state; None for a policy over action values."""
    if policy.kind not in ("uniform", "fixed", "sign"):
        return None
    names = spec.world.sensor_names()
    return np.array([policy_probs(policy, row, names, chain.num_actions) for row in state_sensors(spec, chain)])


def _matrix(chain: Model, weight: np.ndarray) -> np.ndarray:
    """[N, N] sum over the transitions s -> s' of weight[k] (terminal ones left out)."""
    out = np.zeros((len(chain.states), len(chain.states)))
    inside = chain.dst >= 0
    np.add.at(out, (chain.src[inside], chain.dst[inside]), weight[inside])
    return out


def state_distribution(spec: RunSpec, chain: Model) -> np.ndarray | None:
    """[N] d: the behaviour's expected visits per episode, normalised (the stationary distribution of a world
    that never ends); None for a behaviour over action values."""
    b = _probs(spec.behaviour, spec, chain)
    if b is None:
        return None
    P = _matrix(chain, b[chain.src, chain.act] * chain.prob)
    n = len(chain.states)
    if (P.sum(axis=1) < 1.0 - 1e-12).any():
        visits = np.linalg.solve((np.eye(n) - P).T, chain.start)
    else:  # never ends: d (I - P) = 0, sum d = 1
        system = np.vstack([(np.eye(n) - P).T, np.ones((1, n))])
        visits = np.linalg.lstsq(system, np.r_[np.zeros(n), 1.0], rcond=None)[0]
    return visits / visits.sum()


@dataclass(frozen=True)
class DemonTruth:
    """A demon's exact values and TD fixed point over the states (see the module), and what its errors need."""

    states: np.ndarray  # [N] the states' numbers
    exact: np.ndarray  # [N] v_pi
    fixed_point: np.ndarray  # [N] X w*, the TD(lambda) fixed point's values
    distribution: np.ndarray  # [N] d
    features: np.ndarray  # [N, n] X
    lam: float
    M: np.ndarray  # [N, N]
    r: np.ndarray  # [N]
    trace: np.ndarray | None = None  # [N, N] (I - lambda M)^-1; None for lambda 0 (the identity)

    def rmsve(self, values: np.ndarray) -> float:
        """sqrt(sum_s d_s (v_s - v_pi,s)^2)."""
        return float(np.sqrt(self.distribution @ (values - self.exact) ** 2))

    def rms(self, values: np.ndarray) -> float:
        """sqrt(mean_s (v_s - v_pi,s)^2), every state alike."""
        return float(np.sqrt(np.mean((values - self.exact) ** 2)))

    def error(self, values: np.ndarray, weighting: str) -> float:
        return self.rmsve(values) if weighting == "on-policy" else self.rms(values)

    def scale(self, weighting: str) -> float:
        """The size of the truth under the weighting (what a relative error divides by)."""
        return self.error(np.zeros_like(self.exact), weighting)

    def rmspbe(self, values: np.ndarray) -> float:
        """sqrt(g' C^-1 g), g = X' D delta, C = X' D X, delta = (I - lambda M)^-1 (r - (I - M) v): the norm under d
        of the projected expected lambda-return error. The inverse is the one `demon_truth` kept (a product,
        O(N^2), where a solve per call took O(N^3): a fifth of a second at 1000 states, at every checkpoint)."""
        D = self.distribution
        residual = self.r - values + self.M @ values
        delta = self.trace @ residual if self.trace is not None else residual
        g = self.features.T @ (D * delta)
        C = self.features.T @ (D[:, None] * self.features)
        return float(np.sqrt(max(float(g @ np.linalg.pinv(C) @ g), 0.0)))


def demon_truth(horde: Horde, name: str, chain: Model | None = None, spec: RunSpec | None = None,
                cache: dict[object, Any] | None = None) -> DemonTruth | None:  # fmt: skip
    """The demon's truth over the states (see the module); None where the world's transitions are not known, the
    demon learns action values, its question reads predictions or its target policy (or the behaviour) reads
    action values. `spec`: the run's spec when its behaviour changed since the Horde was built (default the
    Horde's). `cache`: shared by calls for demons of one Horde and spec, it keeps what their questions share (the
    behaviour's distribution; a question's M, r and exact values; a question's and lambda's trace solve), each
    a solve over the N states (1000 states: a fifth of a second)."""
    spec = spec if spec is not None else horde.spec
    chain = chain if chain is not None else model_of(spec)
    demon = horde.plan.demons[horde.index[name]]
    if chain is None or demon.action_values:
        return None
    if any(expr_predictions(e) for e in (demon.cumulant, demon.outcome, demon.continuation)):
        return None
    cache = {} if cache is None else cache
    if "d" not in cache:
        cache["d"] = state_distribution(spec, chain)
    pi, d = _probs(demon.policy, spec, chain), cache["d"]
    if pi is None or d is None:
        return None
    n = len(chain.states)
    question = repr((demon.policy, demon.cumulant, demon.outcome, demon.continuation, demon.discount))
    if question not in cache:
        cache[question] = _question(spec, chain, demon, pi)
    if cache[question] is None:
        return None
    M, r, exact = cache[question]
    group = next(g for g in horde.groups if horde.index[name] in g.demons)
    X = group.coder.dense(np.zeros(n), np.zeros(n), sensors=state_sensors(spec, chain))  # [N, n]
    lam = float(demon.lam)
    if (question, lam) not in cache:  # (I - lambda M)^-1 r, and (I - lambda M)^-1 itself (None: lambda 0, I)
        try:
            trace = np.linalg.inv(np.eye(n) - lam * M) if lam != 0.0 else None
        except np.linalg.LinAlgError:  # lambda 1 on a question that never ends: no projected Bellman error
            cache[question, lam] = None
        else:
            cache[question, lam] = (trace, trace @ r if trace is not None else r)
    if cache[question, lam] is None:
        return None
    trace, trace_r = cache[question, lam]
    moved = (np.eye(n) - M) @ X  # [N, n]
    A = X.T @ (d[:, None] * (trace @ moved if trace is not None else moved))  # [n, n], O(N^2 n), not O(N^3)
    b = X.T @ (d * trace_r)
    w = np.linalg.lstsq(A, b, rcond=None)[0]
    return DemonTruth(chain.states, exact, X @ w, d, X, lam, M, r, trace)


def _question(
    spec: RunSpec, chain: Model, demon: Any, pi: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """M [N, N], r [N] and the exact values [N] of a demon's question under its target policy pi [N, A]; None
    where the question has no finite answer (a continuation of 1 on a world that never ends, as a discount of 1
    on Baird's star: I - M is singular)."""
    rows = _rows(spec, chain.obs, chain.reward, chain.terminated.astype(float))
    names = spec.world.sensor_names()
    values = Program([demon.cumulant, demon.outcome, demon.continuation], {n: i for i, n in enumerate(names)},
                     {}).evaluate(rows)  # fmt: skip
    gamma = np.clip(values[:, 2], 0.0, 1.0) * demon.discount
    gamma[chain.terminated] = 0.0
    weight = pi[chain.src, chain.act] * chain.prob  # [K]
    M = _matrix(chain, weight * gamma)
    r = np.zeros(len(chain.states))
    np.add.at(r, chain.src, weight * (values[:, 0] + (1.0 - gamma) * values[:, 1]))
    try:
        return M, r, np.linalg.solve(np.eye(len(chain.states)) - M, r)
    except np.linalg.LinAlgError:
        return None


@dataclass(frozen=True)
class _Projection:
    """What a demon's RMSVE and RMSPBE need beside its values (see `StateErrors`)."""

    column: int  # the demon's index in the Horde
    exact: np.ndarray  # [N] v_pi
    distribution: np.ndarray  # [N] d
    g0: np.ndarray  # [n] X^T D (I - lambda M)^-1 r
    G: np.ndarray  # [n, N] X^T D (I - lambda M)^-1 (I - M)
    C_pinv: np.ndarray  # [n, n] (X^T D X)^+

    @classmethod
    def of(cls, column: int, truth: DemonTruth) -> _Projection:
        n = len(truth.states)
        D = truth.distribution
        weighted = D[:, None] * truth.features  # [N, n]
        K = (truth.trace.T @ weighted if truth.trace is not None else weighted).T  # [n, N] X^T D (I - lambda M)^-1
        C = truth.features.T @ (D[:, None] * truth.features)  # [n, n]
        return cls(column, truth.exact, D, K @ truth.r, K @ (np.eye(n) - truth.M), np.linalg.pinv(C))

    def errors(self, values: np.ndarray) -> tuple[float, float]:
        """RMSVE and RMSPBE of values [N] (as `DemonTruth.rmsve` and `DemonTruth.rmspbe`)."""
        g = self.g0 - self.G @ values  # [n]
        pbe = max(float(g @ self.C_pinv @ g), 0.0)
        return float(np.sqrt(self.distribution @ (values - self.exact) ** 2)), float(np.sqrt(pbe))


class StateErrors:
    """RMSVE and RMSPBE of a Horde's demons at its current weights, on a world whose transitions are known: the
    online form of `values_report`'s errors (a live run's history records them as it goes).

    RMSVE is weighted by the behaviour's distribution over states (the on-policy distribution mu of Sutton &
    Barto 2018 (9.2) where behaviour and target agree, as the book's figures 9.x weight it), RMSPBE by the same
    distribution with the demon's own lambda. A demon without a truth (action values, a question that reads
    other demons) measures NaN. Use `state_errors` to build one.
    """

    def __init__(self, horde: Horde, chain: Model, projections: list[_Projection]) -> None:
        self.horde = horde
        self.chain = chain
        self._projections = projections
        self._names = [horde.names[p.column] for p in projections]
        self._sensors = state_sensors(horde.spec, chain)  # [N, S]

    def measure(self, state: HordeState) -> tuple[np.ndarray, np.ndarray]:
        """[D] RMSVE and [D] RMSPBE of every demon at the state's weights (NaN: no truth, or diverged)."""
        D = self.horde.num_demons
        rmsve, rmspbe = np.full(D, np.nan), np.full(D, np.nan)
        if not self._projections:
            return rmsve, rmspbe
        n = len(self.chain.states)
        with np.errstate(all="ignore"):
            predicted = self.horde.forward(state, np.zeros(n), np.zeros(n), sensors=self._sensors,
                                           demons=self._names).prediction  # fmt: skip
            for p in self._projections:
                if not state.diverged[p.column]:
                    rmsve[p.column], rmspbe[p.column] = p.errors(predicted[:, p.column])
        return rmsve, rmspbe


def state_errors(horde: Horde, spec: RunSpec | None = None) -> StateErrors | None:
    """The Horde's `StateErrors`; None where its world's transitions are not known (no discrete states to
    measure over: the grid, a stream, a Gymnasium world other than the chains and Baird's star)."""
    spec = spec if spec is not None else horde.spec
    chain = model_of(spec)
    if chain is None:
        return None
    projections: list[_Projection] = []
    cache: dict[object, Any] = {}
    for column, name in enumerate(horde.names):
        truth = demon_truth(horde, name, chain, spec, cache)
        if truth is not None:
            projections.append(_Projection.of(column, truth))
    return StateErrors(horde, chain, projections)


def predictions_at_states(horde: Horde, state: HordeState, chain: Model, names: list[str]) -> np.ndarray:
    """[N, len(names)] the demons' predictions at every non-terminal state, weights frozen."""
    n = len(chain.states)
    forward = horde.forward(state, np.zeros(n), np.zeros(n), sensors=state_sensors(horde.spec, chain), demons=names)
    return forward.prediction[:, [horde.index[name] for name in names]]


def values_report(horde: Horde, state: HordeState, names: list[str]) -> dict[str, dict[str, object]]:
    """Per demon: `states`, `values` (its prediction at every state, in order) and where the truth is known
    `exact`, `fixed_point`, `rmsve` (on-policy weighting), `rms_error` (uniform), `rmspbe` and `weighting`;
    empty where the world's transitions are not known."""
    chain = model_of(horde.spec)
    if chain is None:
        return {}
    predicted = predictions_at_states(horde, state, chain, names)
    out: dict[str, dict[str, object]] = {}
    cache: dict[object, Any] = {}
    for j, name in enumerate(names):
        values = predicted[:, j]
        row: dict[str, object] = {"states": chain.states.tolist(), "values": values.tolist()}
        truth = demon_truth(horde, name, chain, cache=cache)
        if truth is not None:
            row.update(exact=truth.exact.tolist(), fixed_point=truth.fixed_point.tolist(), rmsve=truth.rmsve(values),
                       rms_error=truth.rms(values), rmspbe=truth.rmspbe(values),
                       weighting="the behaviour's distribution over states (on-policy: mu)")  # fmt: skip
        out[name] = row
    return out
