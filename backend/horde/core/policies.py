"""Target and behaviour policy probabilities, for many demons at once.

Policies over action values are computed for a whole stack of demons in one go: `q` has a leading
demon axis and every demon carries its own kind, temperature and epsilon as array entries.
Probabilities are exact, so importance ratios pi / b are exact.
"""

from __future__ import annotations

import numpy as np

# Kind codes of the compiled policies (order matters nowhere but here).
UNIFORM, FIXED, GREEDY, SOFTMAX, EPSILON_GREEDY, OF, SIGN = range(7)
KIND_CODES = {
    "uniform": UNIFORM,
    "fixed": FIXED,
    "greedy": GREEDY,
    "softmax": SOFTMAX,
    "epsilon_greedy": EPSILON_GREEDY,
    "of": OF,
    "sign": SIGN,  # a rule on a sensor's sign (worlds fed from outside: horde.core.external)
}
OWN_VALUE = np.array([GREEDY, SOFTMAX, EPSILON_GREEDY])
# Two action values closer than this count as tied for greedy choices.
TIE_TOLERANCE = 1e-12


def greedy(q: np.ndarray) -> np.ndarray:
    """Greedy probabilities, ties split evenly: [..., A] -> [..., A]."""
    best = q >= q.max(axis=-1, keepdims=True) - TIE_TOLERANCE
    return best / best.sum(axis=-1, keepdims=True)


def softmax(q: np.ndarray, temperature: np.ndarray | float) -> np.ndarray:
    """Boltzmann probabilities exp(q / T) / sum exp(q / T) (thesis section 4.3): [..., A]."""
    z = q / np.asarray(temperature)[..., None]
    z = z - z.max(axis=-1, keepdims=True)
    e = np.exp(z)
    return e / e.sum(axis=-1, keepdims=True)


def epsilon_greedy(q: np.ndarray, epsilon: np.ndarray | float) -> np.ndarray:
    """epsilon / A on every action plus (1 - epsilon) on the greedy ones: [..., A]."""
    eps = np.asarray(epsilon)[..., None]
    return eps / q.shape[-1] + (1.0 - eps) * greedy(q)


def value_policy(q: np.ndarray, kind: np.ndarray, temperature: np.ndarray, epsilon: np.ndarray) -> np.ndarray:
    """Probabilities of greedy / softmax / epsilon-greedy policies over each demon's own action values.

    Args:
        q: [..., D, A] action values.
        kind: [D] kind codes (GREEDY, SOFTMAX or EPSILON_GREEDY; other rows are returned as greedy).
        temperature: [D] softmax temperatures.
        epsilon: [D] exploration rates.

    Returns:
        [..., D, A] probabilities.
    """
    is_softmax = kind == SOFTMAX
    if is_softmax.all():
        return softmax(q, temperature)
    probs = greedy(q)
    if is_softmax.any():
        probs = np.where(is_softmax[:, None], softmax(q, temperature), probs)
    is_eps = kind == EPSILON_GREEDY
    if is_eps.any():
        probs = np.where(is_eps[:, None], epsilon_greedy(q, epsilon), probs)
    return probs


def sample(probs: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """One action per row of [B, A] probabilities, drawn with the caller's generator: [B] int64."""
    cdf = np.cumsum(probs, axis=-1)
    u = np.asarray(rng.random(probs.shape[0]))[:, None] * cdf[:, -1:]
    return np.minimum((u >= cdf).sum(axis=-1), probs.shape[-1] - 1).astype(np.int64)


def sign_policy(reading: float, actions: tuple[int, int], epsilon: float, num_actions: int) -> np.ndarray:
    """The "sign" rule: actions[1] where the sensor reads >= 0, else actions[0]; epsilon spread uniformly.

    Returns:
        [A] probabilities (1 - epsilon) on the chosen action plus epsilon / A on every action.
    """
    probs = np.full(num_actions, epsilon / num_actions)
    probs[actions[1] if reading >= 0.0 else actions[0]] += 1.0 - epsilon
    return probs
