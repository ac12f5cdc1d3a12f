"""The equations of DESIGN section 5 written plainly, for one demon at a time: the tests' oracle.

Nothing here is vectorized or clever: dense feature vectors, a recursive expression interpreter,
per-demon loops. The engine (`simulation.py`, with the trace cut at 0) must equal this to 1e-9.

Why one module of about 500 lines: the oracle reads as one paper per function, and the tests trust one
file for every learner. The learners' step functions take one `Transition` each, so they are interchangeable.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field

import numpy as np

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
    demon_lambda,
    demon_step_size,
)

Vector = np.ndarray
Weights = tuple[Vector, Vector, Vector, float]  # (theta, w, e, delta)
Carried = tuple[Vector, Vector, float, float]  # (theta, e, the number the learner carries to the next step, delta)


@dataclass(frozen=True)
class Transition:
    """What a learner's step reads of one transition, for one demon (DESIGN section 5's symbols).

    Every step function below takes the demon's own weights and traces, one `Transition` and its step
    sizes, so the learners are interchangeable: the same transition can be given to any of them.
    """

    phi_t: Vector  # x_t, the features of s_t (GQ: of s_t and a_t)
    phi_tp1: Vector  # x_{t+1} (GQ: phi-bar_{t+1}, the expected features at s_{t+1} under the target policy)
    r_tp1: float  # the cumulant
    z_tp1: float  # the outcome
    gamma_t: float  # the continuation at s_t (times the discount)
    gamma_tp1: float  # the continuation at s_{t+1}
    rho_t: float  # pi(a_t | s_t) / b(a_t | s_t)
    lam: float  # lambda

    def delta(self, theta: Vector) -> float:
        """The TD error of the weights theta on this transition."""
        r, z, g = self.r_tp1, self.z_tp1, self.gamma_tp1
        return float(r + (1 - g) * z + g * theta @ self.phi_tp1 - theta @ self.phi_t)


def gradient_td(theta: Vector, w: Vector, e: Vector, t: Transition, alpha: float, alpha_w: float) -> Weights:
    """The update GQ(lambda) and GTD(lambda) share, given the new trace e (DESIGN section 5):
    theta += alpha (delta e - gamma_{t+1} (1 - lambda) (w . e) x_{t+1}), w += alpha_w (delta e - (w . x_t) x_t).
    Returns (theta, w, e, delta)."""
    delta = t.delta(theta)
    new_theta = theta + alpha * (delta * e - t.gamma_tp1 * (1 - t.lam) * (w @ e) * t.phi_tp1)
    new_w = w + alpha_w * (delta * e - (w @ t.phi_t) * t.phi_t)
    return new_theta, new_w, e, delta


def gq_step(theta: Vector, w: Vector, e: Vector, t: Transition, alpha: float, alpha_w: float) -> Weights:
    """GQ(lambda) on dense vectors (Maei & Sutton, 2010): the trace e = x_t + gamma_t lambda rho_t e (rho_t
    weighs the past only: x_t is of the action taken). Returns (theta, w, e, delta)."""
    return gradient_td(theta, w, t.phi_t + t.gamma_t * t.lam * t.rho_t * e, t, alpha, alpha_w)


def gtd_step(theta: Vector, w: Vector, e: Vector, t: Transition, alpha: float, alpha_w: float) -> Weights:
    """GTD(lambda) on dense state features: the trace e = rho_t (x_t + gamma_t lambda e). Returns (theta, w, e,
    delta)."""
    return gradient_td(theta, w, t.rho_t * (t.phi_t + t.gamma_t * t.lam * e), t, alpha, alpha_w)


def td_step(theta: Vector, w: Vector, e: Vector, t: Transition, alpha: float, alpha_w: float) -> Weights:
    """Off-policy semi-gradient TD(lambda): no correction, w and alpha_w unused. Returns (theta, w, e, delta)."""
    delta = t.delta(theta)
    e = t.rho_t * (t.phi_t + t.gamma_t * t.lam * e)
    return theta + alpha * delta * e, w, e, delta


def gtd2_step(theta: Vector, w: Vector, e: Vector, t: Transition, alpha: float, alpha_w: float) -> Weights:
    """GTD2(lambda) (Sutton, Maei, Precup, Bhatnagar, Silver, Szepesvari & Wiewiora 2009; with lambda and rho as
    Ghiassian & Sutton 2021 write it): the trace e = rho_t (x_t + gamma_t lambda e),
    theta += alpha ((w . x_t) x_t - gamma_{t+1} (1 - lambda) (w . e) x_{t+1}), w += alpha_w (delta e - (w . x_t) x_t).
    Returns (theta, w, e, delta)."""
    e = t.rho_t * (t.phi_t + t.gamma_t * t.lam * e)
    delta = t.delta(theta)
    w_dot_x = w @ t.phi_t
    new_theta = theta + alpha * (w_dot_x * t.phi_t - t.gamma_tp1 * (1 - t.lam) * (w @ e) * t.phi_tp1)
    return new_theta, w + alpha_w * (delta * e - w_dot_x * t.phi_t), e, delta


def gtd1_step(theta: Vector, u: Vector, e: Vector, t: Transition, alpha: float, beta: float) -> Weights:
    """The original GTD (Sutton, Szepesvari & Maei 2008), lambda = 0, rho_t in the trace e = rho_t x_t:
    theta += alpha (x_t - gamma_{t+1} x_{t+1}) (u . e), u += beta (delta e - u). Returns (theta, u, e, delta)."""
    if t.lam != 0.0:
        raise ValueError("the original GTD is defined for lambda = 0 only")
    e = t.rho_t * t.phi_t
    delta = t.delta(theta)
    return theta + alpha * (t.phi_t - t.gamma_tp1 * t.phi_tp1) * (u @ e), u + beta * (delta * e - u), e, delta


STEPS = {"gq": gq_step, "gtd": gtd_step, "td": td_step, "gtd2": gtd2_step, "gtd1": gtd1_step}


def tdrc_step(theta: Vector, w: Vector, e: Vector, t: Transition, alpha: float, alpha_h: float, beta: float) -> Weights:
    """TDRC(lambda) (Ghiassian, Patterson, Garg, Gupta, White & White 2020): GTD(lambda) whose h (here w) learns
    at alpha_h and loses alpha_h beta h at every step:
    theta += alpha (delta e - gamma_{t+1} (1 - lambda) (h . e) x_{t+1}),
    h += alpha_h (delta e - (h . x_t) x_t) - alpha_h beta h. Returns (theta, h, e, delta)."""
    new_theta, new_h, e, delta = gtd_step(theta, w, e, t, alpha, alpha_h)
    return new_theta, new_h - alpha_h * beta * w, e, delta


def true_online_td_step(theta: Vector, e: Vector, v_old: float, t: Transition, alpha: float) -> Carried:
    """True online TD(lambda) with a dutch trace, off-policy form (van Hasselt, Mahmood & Sutton 2014;
    van Seijen, Mahmood, Pilarski, Machado & Sutton 2016, JMLR 17(145)); rho = 1 gives van Seijen &
    Sutton 2014. v_old is theta_{t-1} . phi_t. Returns (theta, e, v_old for the next step, delta)."""
    phi_t, gamma_t, rho_t, lam = t.phi_t, t.gamma_t, t.rho_t, t.lam
    v_t, v_tp1 = theta @ phi_t, theta @ t.phi_tp1
    delta = t.r_tp1 + (1 - t.gamma_tp1) * t.z_tp1 + t.gamma_tp1 * v_tp1 - v_t
    e = rho_t * (gamma_t * lam * e + alpha * (1 - rho_t * gamma_t * lam * (e @ phi_t)) * phi_t)
    theta = theta + delta * e + (v_t - v_old) * (e - alpha * rho_t * phi_t)
    return theta, e, float(v_tp1), float(delta)


def true_online_gtd_step(
    theta: Vector, w: Vector, e: Vector, e_grad: Vector, e_w: Vector, v_old: float, rho_prev: float, t: Transition,
    alpha: float, alpha_w: float,
) -> tuple[Vector, Vector, Vector, Vector, Vector, float, float]:  # fmt: skip
    """True online GTD(lambda) (van Hasselt, Mahmood & Sutton 2014, Algorithm 2), constant lambda.

    Three traces: the dutch trace e of theta, the accumulating trace e_grad of the correction term, and
    the dutch trace e_w of w (decayed with rho_{t-1}). Returns (theta, w, e, e_grad, e_w, v_old, delta).
    """
    phi_t, phi_tp1, gamma_t, gamma_tp1, rho_t, lam = t.phi_t, t.phi_tp1, t.gamma_t, t.gamma_tp1, t.rho_t, t.lam
    v_t, v_tp1 = theta @ phi_t, theta @ phi_tp1
    delta = t.r_tp1 + (1 - gamma_tp1) * t.z_tp1 + gamma_tp1 * v_tp1 - v_t
    e = rho_t * (gamma_t * lam * e + alpha * (1 - rho_t * gamma_t * lam * (e @ phi_t)) * phi_t)
    e_grad = rho_t * (gamma_t * lam * e_grad + phi_t)
    e_w = rho_prev * gamma_t * lam * e_w + alpha_w * (1 - rho_prev * gamma_t * lam * (e_w @ phi_t)) * phi_t
    new_theta = (
        theta
        + delta * e
        + (v_t - v_old) * (e - alpha * rho_t * phi_t)
        - alpha * gamma_tp1 * (1 - lam) * (w @ e_grad) * phi_tp1
    )
    new_w = w + rho_t * delta * e_w - alpha_w * (w @ phi_t) * phi_t
    return new_theta, new_w, e, e_grad, e_w, float(v_tp1), float(delta)


def etd_step(theta: Vector, e: Vector, followon: float, rho_prev: float, t: Transition, alpha: float) -> Carried:
    """Emphatic TD(lambda) (Sutton, Mahmood & White 2016, JMLR 17(73), equations 21-23), constant lambda,
    interest i_t = 1 in every state (as the engine).

    F_t = rho_{t-1} gamma_t F_{t-1} + i_t (the followon trace), M_t = lambda i_t + (1 - lambda) F_t (the
    emphasis), e_t = rho_t (gamma_t lambda e_{t-1} + M_t phi_t), theta += alpha delta_t e_t.
    Returns (theta, e, F_t, delta).
    """
    interest = 1.0
    followon = rho_prev * t.gamma_t * followon + interest
    emphasis = t.lam * interest + (1 - t.lam) * followon
    e = t.rho_t * (t.gamma_t * t.lam * e + emphasis * t.phi_t)
    delta = t.delta(theta)
    return theta + alpha * delta * e, e, float(followon), delta


def adaptive_td_step(
    theta: Vector, e: Vector, alphas: Vector, h: Vector, v: Vector, t: Transition, mode: str, meta: float, tau: float
) -> tuple[Vector, Vector, Vector, Vector, Vector, float]:
    """TD(lambda) with a step size per weight, adapted online (mode "tidbd" or "autostep").

    TIDBD(lambda), semi-gradient (Kearney, Veeriah, Travnik, Pilarski & Sutton 2019, Algorithm 2), with
    beta = log alpha: alpha_i *= exp(theta_meta delta phi_i h_i); theta += alpha delta e;
    h_i = h_i [1 - alpha_i phi_i e_i]^+ + alpha_i delta e_i.
    Autostep (Mahmood, Sutton, Degris & Pilarski 2012, Algorithm 1) for TD(lambda), as AutoTIDBD
    (Kearney et al. 2019) builds it: the meta step divided by the normaliser
    v_i = max(|delta phi_i h_i|, v_i + alpha_i phi_i e_i (|delta phi_i h_i| - v_i) / tau), and every alpha
    divided by M = max(1, sum_i alpha_i e_i (phi_i - gamma_tp1 phi'_i)), the effective step size: the
    fraction of delta that this step removes, so that no step overshoots. Returns (theta, e, alphas, h, v,
    delta).
    """
    phi_t = t.phi_t
    delta = t.delta(theta)
    e = t.rho_t * (phi_t + t.gamma_t * t.lam * e)
    sample = delta * phi_t * h  # the meta-gradient sample of each weight's log step size
    if mode == "autostep":
        v = np.maximum(np.abs(sample), v + alphas * phi_t * e * (np.abs(sample) - v) / tau)
        ratio = np.divide(sample, v, out=np.zeros_like(v), where=v != 0)
        alphas = alphas * np.exp(meta * ratio)
        alphas = alphas / max(float(alphas @ (e * (phi_t - t.gamma_tp1 * t.phi_tp1))), 1.0)
    else:
        alphas = alphas * np.exp(meta * sample)
    theta = theta + alphas * delta * e
    h = h * np.maximum(1 - alphas * phi_t * e, 0.0) + alphas * delta * e
    return theta, e, alphas, h, v, delta


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


def hashed_sensor_tiles(
    spec: FeatureSpec, sensors: dict[str, float], bounds: dict[str, tuple[float, float]] | None = None
) -> list[int]:
    """Features tiled over sensors (kind "sensors"): one tile per sensor and tiling, hashed into `size`.

    Key (sensor s, tiling t, tile) -> (key * 2654435761 mod 2^32) mod size; a hash already taken in this
    state moves to the next free entry. Plain Python integers, no wrap-around.
    """
    size = spec.size or 0
    taken: list[int] = []
    for s, tiled in enumerate(spec.sensors or []):
        world = (bounds or {}).get(tiled.sensor, (-math.inf, math.inf))
        low = world[0] if tiled.low is None else tiled.low
        high = world[1] if tiled.high is None else tiled.high
        u = (sensors[tiled.sensor] - low) / (high - low)
        for t in range(spec.tilings):
            tile = min(max(math.floor(u * spec.tiles + t / spec.tilings), 0), spec.tiles)
            index = (((s * spec.tilings + t) * (spec.tiles + 1) + tile) * 2654435761) % 2**32 % size
            while index in taken:
                index = (index + 1) % size
            taken.append(index)
    return taken


def _scaled_inputs(spec: FeatureSpec, sensors: dict[str, float], bounds: dict[str, tuple[float, float]]) -> list[float]:
    """The sensors a basis reads, each scaled from its range (its own, else the world's) to [0, 1] and clipped."""
    out = []
    for read in spec.sensors or []:
        world = bounds.get(read.sensor, (-math.inf, math.inf))
        low = world[0] if read.low is None else read.low
        high = world[1] if read.high is None else read.high
        out.append(min(max((sensors[read.sensor] - low) / (high - low), 0.0), 1.0))
    return out


def basis_features(spec: FeatureSpec, s: list[float]) -> list[float]:
    """The values of a polynomial, Fourier, RBF or linear basis at the scaled inputs s (Sutton & Barto 2018,
    section 9.5): every exponent (or centre) vector c in lexicographic order."""
    if spec.kind == "linear":
        return [*s, 1.0]
    if spec.kind == "rbf":
        count = spec.centres or 1
        grid = [0.5] if count == 1 else [j / (count - 1) for j in range(count)]
        sigma = spec.width if spec.width is not None else (1.0 / (count - 1) if count > 1 else 1.0)
        return [math.exp(-sum((a - b) ** 2 for a, b in zip(s, c, strict=True)) / (2 * sigma**2))
                for c in itertools.product(grid, repeat=len(s))]  # fmt: skip
    values = []
    for c in itertools.product(range((spec.order or 0) + 1), repeat=len(s)):
        if spec.kind == "polynomial":
            values.append(math.prod(a**k for a, k in zip(s, c, strict=True)))
        else:
            values.append(math.cos(math.pi * sum(k * a for a, k in zip(s, c, strict=True))))
    return values


def state_features(
    spec: FeatureSpec,
    x: float,
    y: float,
    width: float,
    height: float,
    condition: float,
    sensors: dict[str, float] | None = None,
    bounds: dict[str, tuple[float, float]] | None = None,
) -> np.ndarray:
    """The dense state feature vector of one state: binary for the grid's kinds and tiled sensors; a table
    row's values (an index listed twice adds up); a basis' values over the sensors (`bounds`: the world's
    ranges, for sensors that give none)."""

    def cell(u: float, parts: int) -> int:
        return min(max(math.floor(u * parts), 0), parts - 1)

    phi = np.zeros(spec.base_size())
    u, v = x / width, y / height
    if spec.kind in ("polynomial", "fourier", "rbf", "linear"):
        assert sensors is not None, "a basis over sensors needs the sensors"
        phi[:] = basis_features(spec, _scaled_inputs(spec, sensors, bounds or {}))
    elif spec.kind == "sensors":
        assert sensors is not None, "features tiled over sensors need the sensors"
        phi[hashed_sensor_tiles(spec, sensors, bounds or {})] = 1
        phi[-1] = 1
    elif spec.kind == "table":
        assert sensors is not None and spec.sensor is not None and spec.table, "table features need the sensors"
        row = min(max(round(sensors[spec.sensor]), 0), len(spec.table) - 1)
        values = spec.values[row] if spec.values is not None else [1.0] * len(spec.table[row])
        for index, value in zip(spec.table[row], values, strict=True):
            phi[index] += value
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
    """Plain greedy / softmax / epsilon-greedy probabilities over the A action values q [A]."""
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
    mode: str = "constant"  # step-size mode
    meta: float = 0.0  # autostep's mu / tidbd's theta
    tau: float = 1e4  # autostep's tau
    alphas: np.ndarray = field(default_factory=lambda: np.zeros(0))  # per-weight step sizes (adaptive modes)
    h: np.ndarray = field(default_factory=lambda: np.zeros(0))  # adaptive modes' h
    v: np.ndarray = field(default_factory=lambda: np.zeros(0))  # autostep's normaliser
    e_grad: np.ndarray = field(default_factory=lambda: np.zeros(0))  # true online GTD's second and third traces
    e_w: np.ndarray = field(default_factory=lambda: np.zeros(0))
    v_old: float = 0.0  # true online learners: theta_{t-1} . phi_t
    rho_prev: float = 0.0  # rho_{t-1}
    followon: float = 0.0  # ETD's F
    phi_state_t: np.ndarray = field(default_factory=lambda: np.zeros(0))
    pi_t: np.ndarray = field(default_factory=lambda: np.zeros(0))  # pi(. | s_t) [A], set by `observe`
    prediction: float = 0.0
    delta: float = 0.0


class ReferenceHorde:
    """The plain Horde: fed the engine's transitions, it learns each demon separately.

    `observe` starts an episode at a state; `learn` takes one transition (the action taken, its
    behaviour probability, the next position and the sensors there). Any world kind: the grid's four
    actions or a Gymnasium / stream world's A (`spec.world.num_actions()`); outside the grid there is no
    position (features are tiled over sensors, and x, y go unused).
    """

    def __init__(self, spec: RunSpec) -> None:
        self.spec = spec
        self.num_actions = spec.world.num_actions()
        grid = spec.world.kind == "grid"
        self.width, self.height = (spec.grid.width, spec.grid.height) if grid else (1.0, 1.0)
        self.order = check_demon_graph(spec)
        self.bounds = spec.world.sensor_bounds()
        self._sensors: dict[str, float] | None = None
        self.demons: dict[str, ReferenceDemon] = {}
        for d in spec.demons:
            features = d.features or spec.features
            n = features.state_size() * (self.num_actions if d.action_values else 1)
            k = features.active_count()
            lam = demon_lambda(d, spec.learning)
            alpha = (d.alpha if d.alpha is not None else spec.learning.alpha) / k
            alpha_w = (d.alpha_w if d.alpha_w is not None else spec.learning.alpha_w) / k
            mode, meta = demon_step_size(d, spec.learning)
            theta = np.zeros(n) if d.initial_weights is None else np.array(d.initial_weights, dtype=float)
            self.demons[d.name] = ReferenceDemon(
                d, features, lam, alpha, alpha_w, theta, np.zeros(n), np.zeros(n),
                mode=mode, meta=meta, tau=spec.learning.autostep_tau, alphas=np.full(n, alpha), h=np.zeros(n),
                v=np.zeros(n), e_grad=np.zeros(n), e_w=np.zeros(n),
            )  # fmt: skip

    def _phi_state(self, demon: ReferenceDemon, x: float, y: float) -> np.ndarray:
        condition = demon.features.condition
        cond_value = self.demons[condition.demon].prediction if condition else 0.0
        return state_features(demon.features, x, y, self.width, self.height, cond_value, self._sensors, self.bounds)

    def _phi_sa(self, phi_state: np.ndarray, action: int) -> np.ndarray:
        phi = np.zeros(self.num_actions * len(phi_state))
        phi[action * len(phi_state) : (action + 1) * len(phi_state)] = phi_state
        return phi

    def q_values(self, demon: ReferenceDemon, phi_state: np.ndarray) -> np.ndarray:
        return np.array([demon.theta @ self._phi_sa(phi_state, a) for a in range(self.num_actions)])

    def _policy(self, demon: ReferenceDemon, phi_state: np.ndarray) -> np.ndarray:
        policy = demon.spec.policy
        A = self.num_actions
        if policy.kind == "uniform":
            return np.full(A, 1.0 / A)
        if policy.kind == "fixed":
            return np.array(policy.probabilities, dtype=float)
        if policy.kind == "sign":  # (1 - epsilon) on actions[1] where the sensor reads >= 0, else on actions[0]
            assert policy.sensor is not None and policy.actions is not None and self._sensors is not None
            chosen = policy.actions[1] if self._sensors[policy.sensor] >= 0.0 else policy.actions[0]
            probs = np.full(A, policy.epsilon / A)
            probs[chosen] += 1.0 - policy.epsilon
            return probs
        if policy.kind == "of":
            assert policy.demon is not None
            return self.demons[policy.demon].pi_t.copy()
        return value_policy(policy.kind, self.q_values(demon, phi_state), policy.temperature, policy.epsilon)

    def _prediction(self, demon: ReferenceDemon, phi_state: np.ndarray, pi: np.ndarray) -> float:
        if demon.spec.action_values:
            return float(sum(pi[a] * (demon.theta @ self._phi_sa(phi_state, a)) for a in range(self.num_actions)))
        return float(demon.theta @ phi_state)

    def observe(self, x: float, y: float, sensors: dict[str, float] | None = None) -> None:
        """An episode starts at (x, y) (sensors: read there): traces to zero, reset-each-episode demons forget."""
        self._sensors = sensors
        for name in self.order:
            demon = self.demons[name]
            demon.e = np.zeros_like(demon.e)
            demon.gamma_t = 0.0  # nothing flows back across an episode start (ETD's followon F restarts)
            demon.e_grad = np.zeros_like(demon.e)
            demon.e_w = np.zeros_like(demon.e)
            if demon.spec.reset == "episode":
                demon.theta = np.zeros_like(demon.theta)
                demon.w = np.zeros_like(demon.w)
                demon.alphas = np.full_like(demon.alphas, demon.alpha)
                demon.h = np.zeros_like(demon.h)
                demon.v = np.zeros_like(demon.v)
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
            if spec.action_values:
                phi_t = self._phi_sa(demon.phi_state_t, action)
                phi_next = sum(pi_tp1[a] * self._phi_sa(phi_state_tp1, a) for a in range(self.num_actions))
            else:
                phi_t, phi_next = demon.phi_state_t, phi_state_tp1
            self._step(demon, Transition(phi_t, np.asarray(phi_next), r, z, demon.gamma_t, gamma_tp1, rho, demon.lam))
            demon.gamma_t = gamma_tp1
            demon.phi_state_t = phi_state_tp1
            demon.pi_t = self._policy(demon, phi_state_tp1)
            demon.prediction = self._prediction(demon, phi_state_tp1, demon.pi_t)
            predictions[name] = demon.prediction

    @staticmethod
    def _step(d: ReferenceDemon, t: Transition) -> None:
        """One learner step of demon d, by its learner and step-size mode."""
        learner = d.spec.learner
        if d.mode != "constant":
            d.theta, d.e, d.alphas, d.h, d.v, d.delta = adaptive_td_step(
                d.theta, d.e, d.alphas, d.h, d.v, t, d.mode, d.meta, d.tau
            )
        elif learner == "true_online_td":
            d.theta, d.e, d.v_old, d.delta = true_online_td_step(d.theta, d.e, d.v_old, t, d.alpha)
        elif learner == "true_online_gtd":
            d.theta, d.w, d.e, d.e_grad, d.e_w, d.v_old, d.delta = true_online_gtd_step(
                d.theta, d.w, d.e, d.e_grad, d.e_w, d.v_old, d.rho_prev, t, d.alpha, d.alpha_w
            )
        elif learner == "etd":
            d.theta, d.e, d.followon, d.delta = etd_step(d.theta, d.e, d.followon, d.rho_prev, t, d.alpha)
        elif learner == "tdrc":  # h at eta alpha (alpha already divided by the active count)
            eta, beta = d.spec.parameter("eta"), d.spec.parameter("beta")
            d.theta, d.w, d.e, d.delta = tdrc_step(d.theta, d.w, d.e, t, d.alpha, eta * d.alpha, beta)
        else:
            d.theta, d.w, d.e, d.delta = STEPS[learner](d.theta, d.w, d.e, t, d.alpha, d.alpha_w)
        d.rho_prev = t.rho_t

    @staticmethod
    def effective_alpha(demon: ReferenceDemon) -> float:
        """The step size a demon takes now: alpha times the active count, or the sum of its per-weight step
        sizes over the active features (adaptive modes)."""
        if demon.mode == "constant":
            return demon.alpha * demon.features.active_count()
        return float(demon.alphas[demon.phi_state_t != 0].sum())
