"""The demons of a scale `Layout`, learned one at a time by `reference.py`'s plain equations.

The oracle of the scale engine's tests, and the baseline of `horde bench`: dense feature vectors, one
trace per demon, no cut, float64, and each demon's own target policy computed from dense dot products,
as `reference.ReferenceHorde` does. It takes the same per-step inputs as `scale.step`.
"""

from __future__ import annotations

import numpy as np

from horde.core import reference
from horde.core.scale import A, Layout


class ReferenceDemons:
    """Plain single-demon learning for some demons of a layout.

    Args:
        layout: the blocks.
        demons: which demons (global indices) to learn; default all.
    """

    def __init__(self, layout: Layout, demons: np.ndarray | None = None) -> None:
        self.layout = layout
        self.demons = np.arange(layout.num_demons) if demons is None else np.asarray(demons, dtype=np.int64)
        self.block_of = np.searchsorted(layout.hi, self.demons, side="right")  # [M]
        self.class_of = layout.demon_class()[self.demons]  # [M] global trace class
        self.n_s = layout.num_features
        self.theta, self.w, self.e = [], [], []
        for b in self.block_of:
            n = layout.rows(layout.blocks[b])
            self.theta.append(np.zeros(n))
            self.w.append(np.zeros(n))
            self.e.append(np.zeros(n))
        self.phi_t = np.zeros(self.n_s)
        self.gamma_t = np.zeros(len(self.demons))
        self.pi_t = np.full((len(self.demons), A), 1.0 / A)
        self.prediction = np.zeros(len(self.demons))

    def _phi(self, x: np.ndarray) -> np.ndarray:
        phi = np.zeros(self.n_s)
        phi[x] = 1.0
        return phi

    def _phi_sa(self, phi: np.ndarray, action: int) -> np.ndarray:
        out = np.zeros(A * self.n_s)
        out[action * self.n_s : (action + 1) * self.n_s] = phi
        return out

    def _policy(self, m: int, phi: np.ndarray, given: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
        """(pi, q) of demon m at a state: its own policy over dense action values, or the given one."""
        block = self.layout.blocks[self.block_of[m]]
        q = np.array([self.theta[m] @ self._phi_sa(phi, a) for a in range(A)])
        if block.policy == "given":
            return (np.full(A, 1.0 / A) if given is None else np.asarray(given, dtype=float)), q
        row = self.demons[m] - self.layout.lo[self.block_of[m]]
        assert block.temperature is not None and block.epsilon is not None
        pi = reference.value_policy(block.policy, q, float(block.temperature[row]), float(block.epsilon[row]))
        return pi, q

    def observe(self, x: np.ndarray, pi: np.ndarray | None = None) -> None:
        """Traces to zero; read the first state (pi: [C, A] given policies, as in `scale.observe`)."""
        self.phi_t = self._phi(x)
        self.gamma_t[:] = 0.0
        for m, b in enumerate(self.block_of):
            self.e[m] = np.zeros_like(self.e[m])
            if self.layout.blocks[b].learner == "gq":
                self.pi_t[m], q = self._policy(m, self.phi_t, None if pi is None else pi[self.class_of[m]])
                self.prediction[m] = float(self.pi_t[m] @ q)
            else:
                self.prediction[m] = float(self.theta[m] @ self.phi_t)

    def step(
        self,
        action: int,
        b_prob: float,
        x_tp1: np.ndarray,
        r_tp1: np.ndarray,
        z_tp1: np.ndarray,
        gamma_tp1: np.ndarray,
        rho_t: np.ndarray | None = None,
        pi_tp1: np.ndarray | None = None,
    ) -> np.ndarray:
        """One transition for each demon, as `scale.step` (same arguments); returns delta [M]."""
        phi_tp1 = self._phi(x_tp1)
        delta = np.zeros(len(self.demons))
        for m, (d, b, c) in enumerate(zip(self.demons, self.block_of, self.class_of, strict=True)):
            block = self.layout.blocks[b]
            row = d - self.layout.lo[b]
            given = None if pi_tp1 is None else pi_tp1[c]
            g1 = float(gamma_tp1[c])
            if block.learner == "gq":
                pi_next, _ = self._policy(m, phi_tp1, given)
                phi_t = self._phi_sa(self.phi_t, action)
                phi_next = sum(pi_next[a] * self._phi_sa(phi_tp1, a) for a in range(A))
            else:
                phi_t, phi_next = self.phi_t, phi_tp1
            given_rho = 1.0 if rho_t is None else float(rho_t[c])
            rho = self.pi_t[m, action] / b_prob if block.policy != "given" else given_rho
            self.theta[m], self.w[m], self.e[m], delta[m] = reference.STEPS[block.learner](
                self.theta[m],
                self.w[m],
                self.e[m],
                phi_t,
                np.asarray(phi_next),
                float(r_tp1[d]),
                float(z_tp1[d]),
                float(self.gamma_t[m]),
                g1,
                rho,
                block.lam,
                float(block.alpha[row]),
                float(block.alpha_w[row]),
            )
            self.gamma_t[m] = g1
            if block.learner == "gq":
                self.pi_t[m], q = self._policy(m, phi_tp1, given)
                self.prediction[m] = float(self.pi_t[m] @ q)
            else:
                self.prediction[m] = float(self.theta[m] @ phi_tp1)
        self.phi_t = phi_tp1
        return delta
