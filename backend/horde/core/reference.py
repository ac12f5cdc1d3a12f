"""The equations of DESIGN section 5 written plainly, for one demon at a time: the tests' oracle.

Nothing here is vectorized or clever: dense feature vectors, a recursive expression interpreter,
per-demon loops. The engine (`simulation.py`, with the trace cut at 0) must equal this to 1e-9.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from horde.core.world import NUM_ACTIONS
from horde.spec import (
    AddExpr,
    DemonSpec,
    Expr,
    FeatureSpec,
    IfExpr,
    MaxExpr,
    MinExpr,
    MulExpr,
    PredictionExpr,
    RunSpec,
    SensorExpr,
    check_demon_graph,
)


def gq_step(
    theta: np.ndarray,
    w: np.ndarray,
    e: np.ndarray,
    phi_t: np.ndarray,
    phi_bar_tp1: np.ndarray,
    r_tp1: float,
    z_tp1: float,
    gamma_t: float,
    gamma_tp1: float,
    rho_t: float,
    lam: float,
    alpha: float,
    alpha_w: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """GQ(lambda) on dense vectors (Maei & Sutton, 2010). Returns (theta, w, e, delta)."""
    delta = r_tp1 + (1 - gamma_tp1) * z_tp1 + gamma_tp1 * theta @ phi_bar_tp1 - theta @ phi_t
    e = phi_t + gamma_t * lam * rho_t * e
    new_theta = theta + alpha * (delta * e - gamma_tp1 * (1 - lam) * (w @ e) * phi_bar_tp1)
    new_w = w + alpha_w * (delta * e - (w @ phi_t) * phi_t)
    return new_theta, new_w, e, float(delta)


def gtd_step(
    theta: np.ndarray,
    w: np.ndarray,
    e: np.ndarray,
    phi_t: np.ndarray,
    phi_tp1: np.ndarray,
    r_tp1: float,
    z_tp1: float,
    gamma_t: float,
    gamma_tp1: float,
    rho_t: float,
    lam: float,
    alpha: float,
    alpha_w: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """GTD(lambda) on dense state features. Returns (theta, w, e, delta)."""
    delta = r_tp1 + (1 - gamma_tp1) * z_tp1 + gamma_tp1 * theta @ phi_tp1 - theta @ phi_t
    e = rho_t * (phi_t + gamma_t * lam * e)
    new_theta = theta + alpha * (delta * e - gamma_tp1 * (1 - lam) * (w @ e) * phi_tp1)
    new_w = w + alpha_w * (delta * e - (w @ phi_t) * phi_t)
    return new_theta, new_w, e, float(delta)


def td_step(
    theta: np.ndarray,
    w: np.ndarray,
    e: np.ndarray,
    phi_t: np.ndarray,
    phi_tp1: np.ndarray,
    r_tp1: float,
    z_tp1: float,
    gamma_t: float,
    gamma_tp1: float,
    rho_t: float,
    lam: float,
    alpha: float,
    alpha_w: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """Off-policy semi-gradient TD(lambda): no correction, w unused. Returns (theta, w, e, delta)."""
    delta = r_tp1 + (1 - gamma_tp1) * z_tp1 + gamma_tp1 * theta @ phi_tp1 - theta @ phi_t
    e = rho_t * (phi_t + gamma_t * lam * e)
    return theta + alpha * delta * e, w, e, float(delta)


STEPS = {"gq": gq_step, "gtd": gtd_step, "td": td_step}


# ----------------------------------------------------------------------------------------------
# Plain questions, features and policies


def evaluate_expr(expr: Expr, sensors: dict[str, float], predictions: dict[str, float]) -> float:
    """Interpret an expression recursively."""
    if isinstance(expr, bool | int | float):
        return float(expr)
    if isinstance(expr, SensorExpr):
        return sensors[expr.sensor]
    if isinstance(expr, PredictionExpr):
        return predictions[expr.prediction]
    if isinstance(expr, AddExpr):
        return sum(evaluate_expr(c, sensors, predictions) for c in expr.add)
    if isinstance(expr, MulExpr):
        return math.prod(evaluate_expr(c, sensors, predictions) for c in expr.mul)
    if isinstance(expr, MinExpr):
        return min(evaluate_expr(c, sensors, predictions) for c in expr.min)
    if isinstance(expr, MaxExpr):
        return max(evaluate_expr(c, sensors, predictions) for c in expr.max)
    assert isinstance(expr, IfExpr)
    branch = expr.then if evaluate_expr(expr.if_, sensors, predictions) != 0 else expr.else_
    return evaluate_expr(branch, sensors, predictions)


def hashed_sensor_tiles(spec: FeatureSpec, sensors: dict[str, float]) -> list[int]:
    """Features tiled over sensors (kind "sensors"): one tile per sensor and tiling, hashed into `size`.

    Key (sensor s, tiling t, tile) -> (key * 2654435761 mod 2^32) mod size; a hash already taken in this
    state moves to the next free entry. Plain Python integers, no wrap-around.
    """
    size = spec.size or 0
    taken: list[int] = []
    for s, tiled in enumerate(spec.sensors or []):
        u = (sensors[tiled.sensor] - tiled.low) / (tiled.high - tiled.low)
        for t in range(spec.tilings):
            tile = min(max(math.floor(u * spec.tiles + t / spec.tilings), 0), spec.tiles)
            index = (((s * spec.tilings + t) * (spec.tiles + 1) + tile) * 2654435761) % 2**32 % size
            while index in taken:
                index = (index + 1) % size
            taken.append(index)
    return taken


def state_features(
    spec: FeatureSpec,
    x: float,
    y: float,
    width: float,
    height: float,
    condition: float,
    sensors: dict[str, float] | None = None,
) -> np.ndarray:
    """The dense binary state feature vector of one point (and its sensors, for kind "sensors")."""

    def cell(u: float, parts: int) -> int:
        return min(max(math.floor(u * parts), 0), parts - 1)

    phi = np.zeros(spec.base_size())
    u, v = x / width, y / height
    if spec.kind == "sensors":
        assert sensors is not None, "features tiled over sensors need the sensors"
        phi[hashed_sensor_tiles(spec, sensors)] = 1
        phi[-1] = 1
    elif spec.kind == "constant":
        phi[0] = 1
    elif spec.kind == "grid":
        phi[cell(u, spec.tiles) * spec.tiles + cell(v, spec.tiles)] = 1
    elif spec.kind == "stripes":
        p = spec.parts
        i, j = cell(u, p), cell(v, p)
        phi[i] = 1
        phi[p + j] = 1
        phi[2 * p + i + j] = 1
        phi[2 * p + 2 * p - 1 + i - j + p - 1] = 1
        phi[-1] = 1
    else:
        side = spec.tiles + 1
        for t in range(spec.tilings):
            ou, ov = (t / spec.tilings) % 1.0, (3 * t / spec.tilings) % 1.0
            i = min(max(math.floor(u * spec.tiles + ou), 0), spec.tiles)
            j = min(max(math.floor(v * spec.tiles + ov), 0), spec.tiles)
            phi[t * side * side + i * side + j] = 1
        phi[-1] = 1
    if spec.condition is None:
        return phi
    block = sum(1 for threshold in spec.condition.thresholds if condition >= threshold)
    full = np.zeros(spec.state_size())
    full[block * len(phi) : (block + 1) * len(phi)] = phi
    return full


def value_policy(kind: str, q: np.ndarray, temperature: float, epsilon: float) -> np.ndarray:
    """Plain greedy / softmax / epsilon-greedy probabilities over 4 action values."""
    best = [a for a in range(len(q)) if q[a] >= max(q) - 1e-12]
    greedy = np.array([1.0 / len(best) if a in best else 0.0 for a in range(len(q))])
    if kind == "greedy":
        return greedy
    if kind == "epsilon_greedy":
        return epsilon / len(q) + (1 - epsilon) * greedy
    exps = np.array([math.exp(v / temperature - max(q) / temperature) for v in q])
    return exps / exps.sum()


# ----------------------------------------------------------------------------------------------
# A plain Horde: one demon at a time, in dependency order


@dataclass
class ReferenceDemon:
    spec: DemonSpec
    features: FeatureSpec
    lam: float
    alpha: float
    alpha_w: float
    theta: np.ndarray
    w: np.ndarray
    e: np.ndarray
    gamma_t: float = 0.0
    phi_state_t: np.ndarray = field(default_factory=lambda: np.zeros(0))
    pi_t: np.ndarray = field(default_factory=lambda: np.full(NUM_ACTIONS, 0.25))
    prediction: float = 0.0
    delta: float = 0.0


class ReferenceHorde:
    """The plain Horde: fed the engine's transitions, it learns each demon separately.

    `observe` starts an episode at a state; `learn` takes one transition (the action taken, its
    behaviour probability, the next position and the sensors there).
    """

    def __init__(self, spec: RunSpec) -> None:
        self.spec = spec
        self.width, self.height = spec.grid.width, spec.grid.height
        self.order = check_demon_graph(spec)
        self._sensors: dict[str, float] | None = None
        self.demons: dict[str, ReferenceDemon] = {}
        for d in spec.demons:
            features = d.features or spec.features
            n = features.state_size() * (NUM_ACTIONS if d.learner == "gq" else 1)
            k = features.active_count()
            lam = d.lambda_ if d.lambda_ is not None else spec.learning.lambda_
            alpha = (d.alpha if d.alpha is not None else spec.learning.alpha) / k
            alpha_w = (d.alpha_w if d.alpha_w is not None else spec.learning.alpha_w) / k
            self.demons[d.name] = ReferenceDemon(
                d, features, lam, alpha, alpha_w, np.zeros(n), np.zeros(n), np.zeros(n)
            )

    def _phi_state(self, demon: ReferenceDemon, x: float, y: float) -> np.ndarray:
        condition = demon.features.condition
        cond_value = self.demons[condition.demon].prediction if condition else 0.0
        return state_features(demon.features, x, y, self.width, self.height, cond_value, self._sensors)

    @staticmethod
    def _phi_sa(phi_state: np.ndarray, action: int) -> np.ndarray:
        phi = np.zeros(NUM_ACTIONS * len(phi_state))
        phi[action * len(phi_state) : (action + 1) * len(phi_state)] = phi_state
        return phi

    def q_values(self, demon: ReferenceDemon, phi_state: np.ndarray) -> np.ndarray:
        return np.array([demon.theta @ self._phi_sa(phi_state, a) for a in range(NUM_ACTIONS)])

    def _policy(self, demon: ReferenceDemon, phi_state: np.ndarray) -> np.ndarray:
        policy = demon.spec.policy
        if policy.kind == "uniform":
            return np.full(NUM_ACTIONS, 1.0 / NUM_ACTIONS)
        if policy.kind == "fixed":
            return np.array(policy.probabilities, dtype=float)
        if policy.kind == "of":
            assert policy.demon is not None
            return self.demons[policy.demon].pi_t.copy()
        return value_policy(policy.kind, self.q_values(demon, phi_state), policy.temperature, policy.epsilon)

    def _prediction(self, demon: ReferenceDemon, phi_state: np.ndarray, pi: np.ndarray) -> float:
        if demon.spec.learner == "gq":
            return float(sum(pi[a] * (demon.theta @ self._phi_sa(phi_state, a)) for a in range(NUM_ACTIONS)))
        return float(demon.theta @ phi_state)

    def observe(self, x: float, y: float, sensors: dict[str, float] | None = None) -> None:
        """An episode starts at (x, y) (sensors: read there): traces to zero, reset-each-episode demons forget."""
        self._sensors = sensors
        for name in self.order:
            demon = self.demons[name]
            demon.e = np.zeros_like(demon.e)
            if demon.spec.reset == "episode":
                demon.theta = np.zeros_like(demon.theta)
                demon.w = np.zeros_like(demon.w)
            demon.phi_state_t = self._phi_state(demon, x, y)
            demon.pi_t = self._policy(demon, demon.phi_state_t)
            demon.prediction = self._prediction(demon, demon.phi_state_t, demon.pi_t)

    def learn(
        self, action: int, b_prob: float, x: float, y: float, sensors: dict[str, float], terminated: bool
    ) -> None:
        """One transition for every demon, in dependency order."""
        predictions = {name: d.prediction for name, d in self.demons.items()}
        self._sensors = sensors
        for name in self.order:
            demon = self.demons[name]
            spec = demon.spec
            r = evaluate_expr(spec.cumulant, sensors, predictions)
            z = evaluate_expr(spec.outcome, sensors, predictions)
            gamma_tp1 = min(max(evaluate_expr(spec.continuation, sensors, predictions), 0.0), 1.0) * spec.discount
            if terminated:
                gamma_tp1 = 0.0
            phi_state_tp1 = self._phi_state(demon, x, y)
            pi_tp1 = self._policy(demon, phi_state_tp1)
            rho = demon.pi_t[action] / b_prob
            if spec.learner == "gq":
                phi_t = self._phi_sa(demon.phi_state_t, action)
                phi_next = sum(pi_tp1[a] * self._phi_sa(phi_state_tp1, a) for a in range(NUM_ACTIONS))
            else:
                phi_t, phi_next = demon.phi_state_t, phi_state_tp1
            step = STEPS[spec.learner]
            demon.theta, demon.w, demon.e, demon.delta = step(
                demon.theta, demon.w, demon.e, phi_t, np.asarray(phi_next), r, z,
                demon.gamma_t, gamma_tp1, rho, demon.lam, demon.alpha, demon.alpha_w,
            )  # fmt: skip
            demon.gamma_t = gamma_tp1
            demon.phi_state_t = phi_state_tp1
            demon.pi_t = self._policy(demon, phi_state_tp1)
            demon.prediction = self._prediction(demon, phi_state_tp1, demon.pi_t)
            predictions[name] = demon.prediction
