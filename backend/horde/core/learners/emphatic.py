"""Emphatic TD(lambda) (Sutton, Mahmood & White 2016, JMLR 17(73)), interest 1 in every state.

The followon trace F and the emphasis M are the same for a whole trace class, so the engine shares the trace
as TD's is. Readable numpy form below; `reference.etd_step` is the oracle. The compiled kernel is TD's
(`td_pass`: one pass over the rows a step, each update owed to the next) with the emphasis in what x_t adds to
the trace: ETD's update, alpha delta_t e_t, has TD's form.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from horde.core.engine.layout import NO_NRT
from horde.core.learners.base import Kernel, OnlineState, check_online, target
from horde.spec.learners import LearnerInfo, register

ETD = register(LearnerInfo(
    name="etd", text="emphatic TD(λ): stable off-policy, no second weight vector",
    paper="Sutton, Mahmood & White 2016",
))  # fmt: skip
ETD_CODE = 5  # the engine's kernel code
KERNELS = (Kernel(ETD_CODE, "etd", keeps_state=True),)


def etd_update(
    state: OnlineState, lam: np.ndarray, alpha: np.ndarray, x_t: np.ndarray, x_tp1: np.ndarray,
    r_tp1: np.ndarray, z_tp1: np.ndarray, gamma_t: np.ndarray, gamma_tp1: np.ndarray, rho_t: np.ndarray,
) -> tuple[OnlineState, np.ndarray]:  # fmt: skip
    """Emphatic TD(lambda) (Sutton, Mahmood & White 2016, JMLR 17(73)), interest 1 in every state:
        F_t = rho_{t-1} gamma_t F_{t-1} + 1,  M_t = lambda + (1 - lambda) F_t,
        e_t = rho_t (gamma_t lambda e_{t-1} + M_t x_t),  theta += alpha delta_t e_t.

    Returns: (new state, delta_t [D]).
    """
    check_online(state, x_t, lam, alpha, r_tp1, z_tp1, gamma_t, gamma_tp1, rho_t)
    _, _, delta = target(state, x_t, x_tp1, r_tp1, z_tp1, gamma_tp1)
    followon = state.rho_prev * gamma_t * state.followon + 1.0  # [D]
    emphasis = lam + (1.0 - lam) * followon  # [D]
    e = rho_t[:, None] * ((gamma_t * lam)[:, None] * state.e + emphasis[:, None] * x_t)  # [D, n]
    theta = state.theta + (alpha * delta)[:, None] * e
    return state._replace(theta=theta, e=e, rho_prev=rho_t, followon=followon), delta


# ----------------------------------------------------------------------------------------------
# The compiled kernel


@njit(**NO_NRT)
def prepare(b, lay, cls, onl, scr):
    """Block b before its columns: each class's followon F_t = rho_{t-1} gamma_t F_{t-1} + 1 and emphasis
    M_t = lambda + (1 - lambda) F_t; its trace will decay by gamma_t lambda rho_t and x_t add rho_t M_t. The rest
    is TD's (`td_pass`): the update is owed to the next step, so that each step is one pass over the rows."""
    ncls, coff, lam_b = lay.ncls[b], lay.coff[b], lay.lam[b]
    for c in range(ncls):
        g_t, rho = cls.gamma[coff + c], cls.rho[coff + c]
        scr.decay[c] = g_t * lam_b * rho
        f = onl.cls_rho_prev[coff + c] * g_t * onl.cls_f[coff + c] + 1.0
        onl.cls_f[coff + c] = f
        scr.add[c] = rho * (lam_b + (1.0 - lam_b) * f)
