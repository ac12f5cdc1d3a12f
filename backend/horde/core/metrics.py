"""Online error measures per demon: TD-error averages, RUPEE and UDE (White, 2015).

RUPEE, the root of the unbiased projected error estimate, tracks sqrt(|h . mean(delta e)|) where h
learns like GQ's secondary weights; UDE, the unexpected demon error, is |mean(delta)| / std(delta).
Both use exponential averages with the unbiased start of White (2015): beta_t = beta0 / tau_t with
tau_t = (1 - beta0) tau_{t-1} + beta0, so early estimates are not biased toward zero.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

RUPEE_ALPHA_H = 0.1  # step size of h, divided by the number of active features like alpha
RUPEE_BETA = 0.01  # averaging rate of delta * e
UDE_BETA = 0.01  # averaging rate of delta and delta^2
UDE_EPSILON = 1e-3  # keeps UDE finite while delta has not varied yet


class MetricsState(NamedTuple):
    h: np.ndarray  # [D, n]
    delta_e: np.ndarray  # [D, n] average of delta * e
    tau_rupee: float
    delta_mean: np.ndarray  # [D] average delta
    delta_square: np.ndarray  # [D] average delta^2
    abs_delta: np.ndarray  # [D] average |delta|
    tau_ude: float


def zeros(num_demons: int, num_features: int) -> MetricsState:
    d = np.zeros(num_demons)
    return MetricsState(
        np.zeros((num_demons, num_features)), np.zeros((num_demons, num_features)), 0.0, d, d.copy(), d.copy(), 0.0
    )


def update(
    state: MetricsState, delta: np.ndarray, e: np.ndarray, x_idx: np.ndarray, x_val: np.ndarray, active: int
) -> MetricsState:
    """Fold one step's TD errors [D] and traces [D, n] (x_t sparse: [k], [k]) into the averages."""
    alpha_h = RUPEE_ALPHA_H / active
    h_dot_x = (state.h[:, x_idx] * x_val).sum(axis=1)  # [D]
    h = state.h + alpha_h * delta[:, None] * e
    h[:, x_idx] -= alpha_h * h_dot_x[:, None] * x_val
    tau_rupee = (1 - RUPEE_BETA) * state.tau_rupee + RUPEE_BETA
    beta = RUPEE_BETA / tau_rupee
    delta_e = (1 - beta) * state.delta_e + beta * delta[:, None] * e
    tau_ude = (1 - UDE_BETA) * state.tau_ude + UDE_BETA
    b = UDE_BETA / tau_ude
    return MetricsState(
        h,
        delta_e,
        tau_rupee,
        (1 - b) * state.delta_mean + b * delta,
        (1 - b) * state.delta_square + b * delta**2,
        (1 - b) * state.abs_delta + b * np.abs(delta),
        tau_ude,
    )


def rupee(state: MetricsState) -> np.ndarray:
    """[D] sqrt(|h . average(delta e)|)."""
    return np.sqrt(np.abs((state.h * state.delta_e).sum(axis=1)))


def ude(state: MetricsState) -> np.ndarray:
    """[D] |average delta| / (std of delta + epsilon)."""
    variance = np.maximum(state.delta_square - state.delta_mean**2, 0.0)
    return np.abs(state.delta_mean) / (np.sqrt(variance) + UDE_EPSILON)
