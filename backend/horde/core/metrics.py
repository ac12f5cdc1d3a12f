"""Online error measures per demon: TD-error averages, RUPEE and UDE (White, 2015).

RUPEE, the root of the unbiased projected error estimate, tracks sqrt(|h . mean(delta e)|) where h
learns like GQ's secondary weights; UDE, the unexpected demon error, is |mean(delta)| / std(delta).
Both use exponential averages with the unbiased start of White (2015): beta_t = beta0 / tau_t with
tau_t = (1 - beta0) tau_{t-1} + beta0, so early estimates are not biased toward zero.

Arrays are in the engine's feature-major form: h and the average of delta e are [n, Db] per block;
this module is the readable numpy form of the engine's compiled metrics (`fast.py`), which keeps the
average scaled lazily so that its decay does not touch every row at every step.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

RUPEE_ALPHA_H = 0.1  # step size of h, divided by the number of active features like alpha
RUPEE_BETA = 0.01  # averaging rate of delta * e
UDE_BETA = 0.01  # averaging rate of delta and delta^2
UDE_EPSILON = 1e-3  # keeps UDE finite while delta has not varied yet


class BlockMetrics(NamedTuple):
    h: np.ndarray  # [n, Db]
    delta_e: np.ndarray  # [n, Db] average of delta * e
    tau_rupee: float
    delta_stats: np.ndarray  # [Db, 3] averages of delta, delta^2, |delta|
    tau_ude: float


def update(state: BlockMetrics, delta: np.ndarray, e: np.ndarray, x_t: np.ndarray, active: int) -> BlockMetrics:
    """Fold one step's TD errors [Db] and traces [n, Db] (each demon's; x_t: [k] rows of x_t) into the averages."""
    alpha_h = RUPEE_ALPHA_H / active
    h_dot_x = state.h[x_t].sum(axis=0)  # [Db]
    h = state.h + alpha_h * e * delta[None, :]
    h[x_t] -= alpha_h * h_dot_x[None, :]
    tau_rupee = (1 - RUPEE_BETA) * state.tau_rupee + RUPEE_BETA
    beta = RUPEE_BETA / tau_rupee
    delta_e = (1 - beta) * state.delta_e + beta * e * delta[None, :]
    tau_ude = (1 - UDE_BETA) * state.tau_ude + UDE_BETA
    b = UDE_BETA / tau_ude
    stats = np.stack([delta, delta**2, np.abs(delta)], axis=1)
    return BlockMetrics(h, delta_e, tau_rupee, (1 - b) * state.delta_stats + b * stats, tau_ude)


def ude_of(delta_stats: np.ndarray) -> np.ndarray:
    """[D] |average delta| / (std of delta + epsilon), from [D, 3] averages of delta, delta^2, |delta|."""
    mean, square = delta_stats[:, 0], delta_stats[:, 1]
    variance = np.maximum(square - mean**2, 0.0)
    return np.abs(mean) / (np.sqrt(variance) + UDE_EPSILON)
