"""GTD2(lambda) and the original GTD: the gradient-TD learners whose theta follows the secondary weights.

The registry's `gtd` is TDC (Maei 2011's GTD(lambda), "linear TD with gradient correction"): theta follows
delta_t e_t and a correction. The two learners here are the earlier ones of the same line, which descend an
objective through the secondary weights alone:

* `gtd2`: GTD2 (Sutton, Maei, Precup, Bhatnagar, Silver, Szepesvari & Wiewiora 2009, "Fast gradient-descent
  methods for temporal-difference learning with linear function approximation"), stochastic gradient descent
  on the MSPBE. With lambda and rho: theta follows A^T w = E[(x_t - gamma_tp1 x_tp1) e_t^T] w, which equals
  E[(w . x_t) x_t - gamma_tp1 (1 - lambda) (w . e_t) x_tp1] under the behaviour (E[x_t e_t^T] = E[x_t x_t^T]
  + lambda E[gamma_tp1 x_tp1 e_t^T] in the stationary process, as E_b[rho_t | s_t] = 1); the form Ghiassian &
  Sutton 2021 write (the collision task's comparison of off-policy learners), with the trace
  e_t = rho_t (x_t + gamma_t lambda e_{t-1}):
      delta_t = r_tp1 + (1 - gamma_tp1) z_tp1 + gamma_tp1 theta . x_tp1 - theta . x_t
      theta  += alpha   ((w . x_t) x_t - gamma_tp1 (1 - lambda) (w . e_t) x_tp1)
      w      += alpha_w (delta_t e_t - (w . x_t) x_t)
  TDC is the same with delta_t e_t in place of (w . x_t) x_t (w estimates E[x x^T]^-1 E[delta e]).
* `gtd1`: the original GTD (Sutton, Szepesvari & Maei 2008, "A convergent O(n) algorithm for off-policy
  temporal-difference learning with linear function approximation"), stochastic gradient descent on the norm of
  the expected TD update, E[rho delta x]^T E[rho delta x]; u estimates E[rho_t delta_t x_t]. Lambda = 0 only
  (the paper's setting; no published form with traces is known here): a demon that sets lambda > 0 is refused,
  and one that leaves it out learns with lambda = 0 whatever [learning] says. With e_t = rho_t x_t:
      theta  += alpha (x_t - gamma_tp1 x_tp1) (u . e_t)
      u      += beta (delta_t e_t - u)            (beta: the demon's alpha_w)
Both fixed points are the TD fixed point (A theta = b), as TDC's: `tests/core/test_gtd2.py` checks it by the
linear solve of `worlds/state_values.py`.

`gtd2_update` and `gtd1_update` below are the readable numpy forms; `reference.gtd2_step`, `gtd1_step` the oracle.

The compiled kernel is GTD's one pass (`gtd_pass.columns`, told what theta follows: `FOLLOWS_W`, `FOLLOWS_U`):
theta's move along x_t is owed to the next step with the rest of the update (`gtd_pass`'s M) and paid in the
same walk. The original GTD's u shrinks by (1 - beta) at every step, which would touch every weight: u is kept
scaled per demon as TDRC keeps h (`tdrc.move_scales`, with its regulariser 1 and no -(u . x) x).
"""

from __future__ import annotations

import numpy as np

from horde.core.learners.base import Kernel, check, td_error
from horde.core.learners.gradient import LearnerParams, LearnerState, dot_sparse
from horde.spec.learners import LearnerInfo, register

GTD2 = register(LearnerInfo(
    name="gtd2", text="GTD2(λ): state values, θ follows w (MSPBE gradient)",
    paper="Sutton, Maei, Precup, Bhatnagar, Silver, Szepesvári & Wiewiora 2009", secondary=True,
))  # fmt: skip
GTD1 = register(LearnerInfo(
    name="gtd1", text="GTD, the original: state values, θ follows u = E[δx] (λ = 0)",
    paper="Sutton, Szepesvári & Maei 2008", secondary=True, traces=False,
))  # fmt: skip
GTD2_CODE, GTD1_CODE = 9, 10  # the engine's kernel codes


def _gtd1_rates(alpha: float, alpha_w: float, parameters: dict[str, float]) -> tuple[float, float, float]:
    """The original GTD's (alpha, beta, 1): u learns at the demon's alpha_w and loses all of itself at that rate
    (TDRC's regulariser, 1)."""
    return alpha, alpha_w, 1.0


KERNELS = (
    Kernel(GTD2_CODE, "gtd2", vectors=2, owes=True),
    Kernel(GTD1_CODE, "gtd1", vectors=2, owes=True, keeps_state=True, scaled_w=True, rates=_gtd1_rates),
)


def _enter(state: LearnerState, x_t: tuple[np.ndarray, np.ndarray], *per_demon: np.ndarray) -> None:
    num_demons = state.theta.shape[0]
    for i, array in enumerate(per_demon):
        check(f"argument {i + 4}", array, (num_demons,))
    check("x_t values", x_t[1], x_t[0].shape)


def gtd2_update(
    state: LearnerState,
    params: LearnerParams,
    x_t: tuple[np.ndarray, np.ndarray],
    x_tp1: tuple[np.ndarray, np.ndarray],
    r_tp1: np.ndarray,
    z_tp1: np.ndarray,
    gamma_t: np.ndarray,
    gamma_tp1: np.ndarray,
    rho_t: np.ndarray,
) -> tuple[LearnerState, np.ndarray]:
    """One GTD2(lambda) step for every demon of the stack (params.correct and rho_in_trace are not read).

    Args: as `gradient.update` (x_tp1: (indices [m], values [m]) of phi(s_{t+1})).
    Returns: (new state, delta_t [D]).
    """
    _enter(state, x_t, r_tp1, z_tp1, gamma_t, gamma_tp1, rho_t)
    theta, w, e = state
    idx, val = x_t
    nxt_idx, nxt_val = x_tp1
    delta = td_error(r_tp1, z_tp1, gamma_tp1, dot_sparse(theta, nxt_idx, nxt_val), dot_sparse(theta, idx, val))  # [D]
    e = e * (gamma_t * params.lam * rho_t)[:, None]  # [D, n]
    e[:, idx] += rho_t[:, None] * val
    w_dot_e, w_dot_x = (w * e).sum(axis=1), dot_sparse(w, idx, val)  # [D] each

    theta = theta.copy()
    theta[:, idx] += (params.alpha * w_dot_x)[:, None] * val
    theta[:, nxt_idx] -= (params.alpha * gamma_tp1 * (1.0 - params.lam) * w_dot_e)[:, None] * nxt_val
    w = w + (params.alpha_w * delta)[:, None] * e
    w[:, idx] -= (params.alpha_w * w_dot_x)[:, None] * val
    return LearnerState(theta, w, e), delta


def gtd1_update(
    state: LearnerState,
    params: LearnerParams,
    x_t: tuple[np.ndarray, np.ndarray],
    x_tp1: tuple[np.ndarray, np.ndarray],
    r_tp1: np.ndarray,
    z_tp1: np.ndarray,
    gamma_t: np.ndarray,
    gamma_tp1: np.ndarray,
    rho_t: np.ndarray,
) -> tuple[LearnerState, np.ndarray]:
    """One step of the original GTD for every demon of the stack: u in `state.w`, beta = params.alpha_w, the
    trace e_t = rho_t x_t (params.lam must be 0; gamma_t is not read).

    Args: as `gtd2_update`.
    Returns: (new state, delta_t [D]).

    Raises:
        ValueError: a lambda other than 0 (no published form).
    """
    _enter(state, x_t, r_tp1, z_tp1, gamma_t, gamma_tp1, rho_t)
    if np.any(params.lam != 0.0):
        raise ValueError("the original GTD is defined for lambda = 0 only")
    theta, u, _ = state
    idx, val = x_t
    nxt_idx, nxt_val = x_tp1
    delta = td_error(r_tp1, z_tp1, gamma_tp1, dot_sparse(theta, nxt_idx, nxt_val), dot_sparse(theta, idx, val))  # [D]
    e = np.zeros_like(theta)  # [D, n]
    e[:, idx] = rho_t[:, None] * val
    u_dot_e = (u * e).sum(axis=1)  # [D]

    theta = theta.copy()
    theta[:, idx] += (params.alpha * u_dot_e)[:, None] * val
    theta[:, nxt_idx] -= (params.alpha * gamma_tp1 * u_dot_e)[:, None] * nxt_val
    u = (1.0 - params.alpha_w)[:, None] * u + (params.alpha_w * delta)[:, None] * e
    return LearnerState(theta, u, e), delta
