"""TDRC(lambda): TD with regularized corrections (Ghiassian, Patterson, Garg, Gupta, White & White 2020, ICML,
"Gradient Temporal-Difference Learning with Regularized Corrections"), a gradient learner that needs little
tuning: TDC's correction, its h learned at eta alpha (the paper: eta = 1) with beta h subtracted (beta = 1).

Per demon, with GTD(lambda)'s trace e_t = rho_t (x_t + gamma_t lambda e_{t-1}) (lambda = 0: the paper's):
    delta_t = r_tp1 + (1 - gamma_tp1) z_tp1 + gamma_tp1 theta . x_tp1 - theta . x_t
    theta  += alpha (delta_t e_t - gamma_tp1 (1 - lambda) (h . e_t) x_tp1)
    h      += alpha_h (delta_t e_t - (h . x_t) x_t) - alpha_h beta h,     alpha_h = eta alpha
`tdrc_update` below is the readable numpy form; `reference.tdrc_step` the oracle.

The compiled kernel is GTD's one pass (`gtd_pass`): the regulariser shrinks all of h at every step, which would
touch every weight; h is kept scaled instead, h = s w with s per demon (`Online.scale`), so that the shrink is
one multiplication of s, and the pass moves w with its step divided by the new s (`move_scales`,
`Scratch.scales`). A scale below SCALE_FLOOR is folded back into w (one pass over the demon's column, about
every 1e5 steps at the default step sizes: `gtd_pass.finish`).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from horde.core.engine.layout import NO_NRT
from horde.core.learners.base import Kernel
from horde.core.learners.gradient import LearnerParams, LearnerState, update
from horde.spec.learners import LearnerInfo, Parameter, register

TDRC = register(LearnerInfo(
    name="tdrc", text="TDRC(λ): TDC with regularized corrections, little tuning (β = 1, h at α)",
    paper="Ghiassian, Patterson, Garg, Gupta, White & White 2020", secondary=True,
    parameters=(
        Parameter("beta", 1.0, 0.0, 1000.0, "the regularisation of h: beta h subtracted at every step"),
        Parameter("eta", 1.0, 0.0, 1000.0, "h's step size over alpha"),
    ),
))  # fmt: skip
TDRC_CODE = 8  # the engine's kernel code
SCALE_FLOOR = 1e-150  # a demon's scale of h is folded back into its w below this


def _rates(alpha: float, alpha_w: float, parameters: dict[str, float]) -> tuple[float, float, float]:
    """TDRC's (alpha, alpha_h, beta): h learns at eta alpha, whatever alpha_w says."""
    return alpha, parameters["eta"] * alpha, parameters["beta"]


KERNELS = (Kernel(TDRC_CODE, "tdrc", vectors=2, owes=True, keeps_state=True, scaled_w=True, rates=_rates),)


def tdrc_update(
    state: LearnerState,
    params: LearnerParams,
    beta: np.ndarray,
    x_t: tuple[np.ndarray, np.ndarray],
    x_tp1: tuple[np.ndarray, np.ndarray],
    r_tp1: np.ndarray,
    z_tp1: np.ndarray,
    gamma_t: np.ndarray,
    gamma_tp1: np.ndarray,
    rho_t: np.ndarray,
) -> tuple[LearnerState, np.ndarray]:
    """One TDRC(lambda) step for every demon of the stack: GTD(lambda) (`gradient.update`, h in w, params.alpha_w
    = eta alpha, params.correct = params.rho_in_trace = 1) and then alpha_w beta h_t subtracted from h.

    Args: as `gradient.update`, and beta [D].
    Returns: (new state, delta_t [D]).
    """
    new, delta = update(state, params, x_t, x_tp1, r_tp1, z_tp1, gamma_t, gamma_tp1, rho_t)
    return new._replace(w=new.w - (params.alpha_w * beta)[:, None] * state.w), delta


# ----------------------------------------------------------------------------------------------
# The compiled kernel: GTD's (`gtd_pass`), with h kept scaled


@njit(**NO_NRT)
def move_scales(b, lay, dem, onl, scr, floor):
    """Each demon's scale of h moves on, s' = s (1 - alpha_h beta), and the gradient pass (`gtd_pass`) takes w's
    step divided by s' (`Scratch.scales[0]`), alpha_h (w . x_t) times s / s' ([1]) and w . e, w . x times s ([2]).
    (`gtd_pass.finish` folds a scale below SCALE_FLOOR back into w.)"""
    lo = lay.block_lo[b]
    for i in range(lay.block_hi[b] - lo):
        d = lo + i
        s = onl.scale[d]
        s_next = s * (1.0 - dem.alpha_w[d] * lay.beta[d])  # a frozen demon (alpha_w 0) keeps its scale
        if s_next == 0.0:  # alpha_h beta = 1 drops h whole at every step (no setting of the paper's comes near)
            s_next = floor  # (SCALE_FLOOR, or float32's: `rows.fold_floor`)
        scr.scales[0, i] = 1.0 / s_next
        scr.scales[1, i] = s / s_next
        scr.scales[2, i] = s
        onl.scale[d] = s_next


@njit(**NO_NRT)
def episode_start(code, other, lay, onl):
    """Demons of the kernels `code` and `other` (TDRC's, and another that keeps w scaled with `move_scales`) that
    forget their weights at an episode start (their w was just set to 0) restart their scale."""
    for b in range(lay.learner.shape[0]):
        if lay.learner[b] != code and lay.learner[b] != other:
            continue
        for s in range(lay.block_lo[b], lay.block_hi[b]):
            if lay.reset[s]:
                onl.scale[s] = 1.0
