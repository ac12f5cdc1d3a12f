"""Blocks of demons with feature-major weights and shared, sparse traces: the one engine's layout.

This module describes the structures; `horde.py` compiles a run's demons into them and the compiled
loop (`fast.py`, with the kernels of `scale_fast.py`) learns with them. It answers three questions of
scale (DESIGN section 6):

* **Stacked weights, feature-major.** A block's weights are one array `[n, Db]`: the weights of one
  feature for all demons of the block are contiguous, so a trace entry `e[j]` updates one contiguous
  run `theta[j, :] += alpha * delta * e[j]`, and the gathers `theta . x` over the active features read
  whole rows.
* **Shared traces.** Demons with the same features, target policy, continuation and lambda have the same
  eligibility trace: rho and the decay `gamma_t * lambda * rho_t` are the same for all of them, and so is
  `x_t`. Such demons form a *trace class* (consecutive demons of a block) with one trace column. The
  per-demon work is then a few multiply-adds per trace entry; the GTD correction needs `w_d . e`, a
  gather of w over the trace's support. Demons that follow their own action values (`policy = "softmax" |
  "greedy" | "epsilon_greedy"`, the control demons) have rho of their own: each is its own class.
* **Sparse traces, cut.** A trace is zero outside the features seen in the last few dozen steps. After
  each step, trace entries below `cut` in magnitude are set to zero; a block's support is the rows
  (features) where any of its classes has a non-zero entry, and only those rows are touched by the
  update. `cut = 0` keeps every non-zero entry and equals `reference.py` to 1e-9; the default
  `TRACE_CUT = 1e-8` is measured against the reference in tests/core/test_engine_vs_reference.py.

Features are binary: the active state-feature indices `x` ([k], distinct, sorted). GQ blocks use
state-action features: action a's block of `n_s` state features starts at row `a * n_s`.

Time indices as everywhere: `x_t, a_t, r_tp1, z_tp1, gamma_t, gamma_tp1, x_tp1`. Per demon d of class c:
    delta_t = r_tp1 + (1 - gamma_tp1) z_tp1 + gamma_tp1 theta . x_bar_tp1 - theta . x_t
    e_t     = s_t x_t + gamma_t lambda rho_t e_{t-1}     (s_t = rho_t for TD/GTD, 1 for GQ)
    theta  += alpha   (delta_t e_t - gamma_tp1 (1 - lambda) (w . e_t) x_bar_tp1)    (no correction for TD)
    w      += alpha_w (delta_t e_t - (w . x_t) x_t)                                 (GTD and GQ)
The step sizes are used as given (divided by the number of active features when a block is built).
"""

from __future__ import annotations

from collections.abc import Hashable, Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np

from horde.core.policies import EPSILON_GREEDY, FIXED, GREEDY, SOFTMAX
from horde.core.world import NUM_ACTIONS

A = NUM_ACTIONS  # actions of GQ blocks
TRACE_CUT = 1e-8  # trace entries below this are set to zero (DESIGN section 6)

Learner = Literal["td", "gtd", "gq", "true_online_td", "true_online_gtd", "etd"]
BlockPolicy = Literal["given", "greedy", "softmax", "epsilon_greedy"]
# Codes of the compiled loop; codes from 3 on are the learners of adaptive_kernels.py ("td+tidbd": TD(lambda)
# with TIDBD step sizes, "td+autostep": with Autostep's).
ONLINE_LEARNERS = ("true_online_td", "true_online_gtd", "etd")  # learned by adaptive_kernels.py
LEARNER_CODES = {"td": 0, "gtd": 1, "gq": 2, "true_online_td": 3, "true_online_gtd": 4, "etd": 5, "td+tidbd": 6,
                 "td+autostep": 7}  # fmt: skip
POLICY_CODES = {"given": FIXED, "greedy": GREEDY, "softmax": SOFTMAX, "epsilon_greedy": EPSILON_GREEDY}


@dataclass(frozen=True)
class Block:
    """Demons that share one feature set, one learner and one lambda; their traces share one support.

    Args:
        learner: "td", "gtd" (state values) or "gq" (action values over A x n_s state-action features).
        alpha: [Db] step sizes of theta, as used in the update.
        alpha_w: [Db] step sizes of w (ignored by TD).
        lam: the block's lambda.
        policy: "given" (target policies supplied by the caller every step, one per trace class) or a
            policy over each demon's own action values (GQ only; every demon is its own class).
        classes: [Db] trace class of each demon of a given-policy block: 0, 1, 2, ... non-decreasing
            (demons of a class are consecutive). Default: one class, one shared trace.
        temperature, epsilon: [Db] of softmax / epsilon-greedy policies (default 1 and 0.1).
    """

    learner: Learner
    alpha: np.ndarray
    alpha_w: np.ndarray
    lam: float
    policy: BlockPolicy = "given"
    classes: np.ndarray | None = None
    temperature: np.ndarray | None = None
    epsilon: np.ndarray | None = None
    step_size: str = "constant"  # or "autostep" / "tidbd" (TD only): per-weight step sizes starting at alpha
    meta: np.ndarray | None = None  # [Db] their meta step sizes

    @property
    def code(self) -> int:
        """The learner's code in the compiled loop (LEARNER_CODES)."""
        return LEARNER_CODES[self.learner if self.step_size == "constant" else f"{self.learner}+{self.step_size}"]

    def __post_init__(self) -> None:
        alpha = np.asarray(self.alpha, dtype=float).ravel()
        object.__setattr__(self, "alpha", alpha)
        _check("alpha_w", np.asarray(self.alpha_w), alpha.shape)
        object.__setattr__(self, "alpha_w", np.asarray(self.alpha_w, dtype=float))
        for name, default in (("temperature", 1.0), ("epsilon", 0.1)):
            value = getattr(self, name)
            value = np.full(alpha.shape, default) if value is None else np.asarray(value, dtype=float)
            _check(name, value, alpha.shape)
            object.__setattr__(self, name, value)
        if self.learner not in LEARNER_CODES or self.policy not in POLICY_CODES:
            raise ValueError(f"unknown learner {self.learner!r} or policy {self.policy!r}")
        if self.step_size != "constant" and f"{self.learner}+{self.step_size}" not in LEARNER_CODES:
            raise ValueError(f"step size {self.step_size!r} is not defined for learner {self.learner!r}")
        if len(alpha) == 0:
            raise ValueError("a block needs at least one demon")
        if self.policy != "given":
            if self.learner != "gq":
                raise ValueError(f"a {self.policy} target policy needs action values: use learner 'gq'")
            if self.classes is not None:
                raise ValueError("own-value demons are each their own trace class")
            classes = np.arange(len(alpha))
        else:
            classes = np.zeros(len(alpha), np.int64) if self.classes is None else np.asarray(self.classes, np.int64)
            _check("classes", classes, alpha.shape)
            if classes[0] != 0 or not ((np.diff(classes) == 0) | (np.diff(classes) == 1)).all():
                raise ValueError("trace classes must be numbered 0, 1, 2, ... with each class's demons consecutive")
        object.__setattr__(self, "classes", classes)

    @property
    def size(self) -> int:
        return len(self.alpha)

    @property
    def num_classes(self) -> int:
        assert self.classes is not None
        return int(self.classes[-1]) + 1


@dataclass(frozen=True)
class Layout:
    """A compiled set of blocks over one feature set: where each block's demons and classes live.

    Demons are numbered block by block (block b owns demons `lo[b] .. hi[b] - 1`), and so are trace
    classes (block b owns classes `class_lo[b] ..`).

    Args:
        blocks: the blocks.
        num_features: n_s, the number of state features.
        active: k, the number of active features in every state.
        cut: the trace cut (0 keeps every non-zero entry).
    """

    blocks: tuple[Block, ...]
    num_features: int
    active: int
    cut: float = TRACE_CUT
    num_actions: int = A  # GQ blocks' action blocks (the world's number of actions)

    def __post_init__(self) -> None:
        object.__setattr__(self, "blocks", tuple(self.blocks))
        if not self.cut >= 0.0:
            raise ValueError("the trace cut must be >= 0")
        if not self.blocks:
            raise ValueError("a layout needs at least one block")

    @property
    def num_demons(self) -> int:
        return sum(b.size for b in self.blocks)

    @property
    def num_classes(self) -> int:
        return sum(b.num_classes for b in self.blocks)

    @property
    def class_lo(self) -> np.ndarray:
        """[B] first trace class of each block."""
        return np.cumsum([0] + [b.num_classes for b in self.blocks])[:-1]

    def demon_class(self) -> np.ndarray:
        """[D] the global trace class of every demon."""
        return np.concatenate([c + b.classes for c, b in zip(self.class_lo, self.blocks, strict=True)])

    def rows(self, block: Block) -> int:
        """Rows of a block's weights: A * n_s for GQ, n_s otherwise."""
        return self.num_features * (self.num_actions if block.learner == "gq" else 1)


def trace_classes(keys: Sequence[Hashable]) -> tuple[np.ndarray, np.ndarray]:
    """Group demons whose traces are the same: equal keys (target policy, continuation, lambda) share one.

    Args:
        keys: [D] one hashable trace key per demon.

    Returns:
        (order [D]: the demons reordered so that each class is consecutive, classes in order of first
        appearance; classes [D]: the class of each demon in that order, for `Block(classes=...)`).
    """
    first: dict[Hashable, int] = {}
    for key in keys:
        first.setdefault(key, len(first))
    labels = np.array([first[key] for key in keys], dtype=np.int64)
    order = np.argsort(labels, kind="stable")
    return order, labels[order]


def _check(name: str, array: np.ndarray, shape: tuple[int, ...]) -> None:
    """The one shape check where arrays enter a block."""
    if array.shape != shape:
        raise ValueError(f"{name} has shape {array.shape}, expected {shape}")
