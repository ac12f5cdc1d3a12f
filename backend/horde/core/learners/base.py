"""What the learners' readable numpy forms share: the one entry check, the TD error, the online learners' state.

Time indices as everywhere: `x_t` the features of s_t (and a_t), `x_tp1` those of s_{t+1}, `gamma_t` the
continuation at s_t, `gamma_tp1` at s_{t+1}. Every array has a leading demon axis [D] but the features,
which the demons of a stack share.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np


def _given_rates(alpha: float, alpha_w: float, parameters: dict[str, float]) -> tuple[float, float, float]:
    """A learner's (alpha, alpha_w, beta) from the demon's: as given, no regulariser."""
    return alpha, alpha_w, 0.0


@dataclass(frozen=True)
class Kernel:
    """What the engine needs of one compiled learner (a learner and a step-size mode).

    Args:
        code: the kernel's code in the compiled step (unique; `horde.core.learners` dispatches on it).
        learner: the declared learner (`horde.spec.learners`).
        step_size: the step-size mode it learns with ("constant", "autostep", "tidbd").
        vectors: per-weight arrays its step reads and writes on the trace's rows, theta included (for the
            bench's count of a step's bytes, `benchmarks/bound.py`).
        owes: it owes part of its update to the next step (`learners.settle` pays it: GQ its correction at x_{t+1},
            GTD and its forms their whole update, `gtd_pass`).
        corrects_every_action: its update moves theta on every action's rows at s_{t+1} (GQ's gradient correction,
            each action weighted by the target policy), which are in no trace but the action taken: the bench counts
            those rows read and written, not only read (`benchmarks/bound.py`).
        dutch: its trace holds alpha (and alpha_w): only demons of one step size share one.
        keeps_state: it keeps numbers beyond the weights and traces (`Online`: snapshots save them).
        scaled_w: its secondary weights are kept scaled per demon (the true w is `Online.scale` times them).
        rates: (alpha, alpha_w, beta) of a demon from its alpha, alpha_w and `parameters` (before the division
            by the active count).
    """

    code: int
    learner: str
    step_size: str = "constant"
    vectors: int = 1
    owes: bool = False
    corrects_every_action: bool = False
    dutch: bool = False
    keeps_state: bool = False
    scaled_w: bool = False
    rates: Callable[[float, float, dict[str, float]], tuple[float, float, float]] = _given_rates


def check(name: str, array: np.ndarray, shape: tuple[int, ...]) -> None:
    """The one shape check at the entry of the core's learning functions."""
    if array.shape != shape:
        raise ValueError(f"{name} has shape {array.shape}, expected {shape}")


def td_error(
    r_tp1: np.ndarray, z_tp1: np.ndarray, gamma_tp1: np.ndarray, v_tp1: np.ndarray, v_t: np.ndarray
) -> np.ndarray:
    """delta_t = r_tp1 + (1 - gamma_tp1) z_tp1 + gamma_tp1 v_tp1 - v_t, every demon at once ([D] each)."""
    return r_tp1 + (1.0 - gamma_tp1) * z_tp1 + gamma_tp1 * v_tp1 - v_t


class OnlineState(NamedTuple):
    """State of the learners below; each uses the fields it needs and passes the others through."""

    theta: np.ndarray  # [D, n]
    w: np.ndarray  # [D, n] true online GTD's secondary weights; adaptive TD's h
    e: np.ndarray  # [D, n] the trace of theta (dutch for the true online learners)
    e_grad: np.ndarray  # [D, n] true online GTD: the correction's trace; autostep: the normaliser v
    e_w: np.ndarray  # [D, n] true online GTD: w's dutch trace; adaptive TD: per-weight step sizes
    v_old: np.ndarray  # [D] true online: theta_{t-1} . x_t
    rho_prev: np.ndarray  # [D] rho_{t-1}
    followon: np.ndarray  # [D] ETD's F


def online_zeros(num_demons: int, num_features: int, alpha: np.ndarray | None = None) -> OnlineState:
    """Zero weights and traces; per-weight step sizes (adaptive TD) start at alpha [D]."""
    shape = (num_demons, num_features)
    start = np.zeros(shape) if alpha is None else np.repeat(np.asarray(alpha, float)[:, None], num_features, axis=1)
    return OnlineState(np.zeros(shape), np.zeros(shape), np.zeros(shape), np.zeros(shape), start,
                       np.zeros(num_demons), np.zeros(num_demons), np.zeros(num_demons))  # fmt: skip


def target(
    state: OnlineState, x_t: np.ndarray, x_tp1: np.ndarray, r_tp1: np.ndarray, z_tp1: np.ndarray,
    gamma_tp1: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
    """(theta . x_t, theta . x_tp1, delta_t), each [D]."""
    v_t, v_tp1 = state.theta @ x_t, state.theta @ x_tp1  # [D]
    return v_t, v_tp1, td_error(r_tp1, z_tp1, gamma_tp1, v_tp1, v_t)


def check_online(state: OnlineState, x_t: np.ndarray, *per_demon: np.ndarray) -> None:
    num_demons, n = state.theta.shape
    check("x_t", x_t, (n,))
    for i, array in enumerate(per_demon):
        check(f"argument {i + 3}", array, (num_demons,))
