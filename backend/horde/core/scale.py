"""Many demons at once: blocks of demons with feature-major weights and shared, sparse traces.

This is the readable numpy path of the Horde-scale engine; `scale_fast.py` runs the same equations as
compiled kernels and the tests hold the two equal. It answers three questions of scale (DESIGN section 6):

* **Stacked weights, feature-major.** A block's weights are one array `[n, Db]`: the weights of one
  feature for all demons of the block are contiguous, so a trace entry `e[j]` updates one contiguous
  run `theta[j, :] += alpha * delta * e[j]`, and the gathers `theta . x` over the active features read
  whole rows. (The small-world engine, `learners.py`, keeps `[D, n]`; `demon_arrays` gives that view.)
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
  `TRACE_CUT = 1e-8` (DESIGN section 6) is measured against the reference in tests/core/test_scale.py.

Features are binary and shared by every block: the active state-feature indices `x` ([k], distinct). GQ blocks
use state-action features: action a's block of `n_s` state features starts at row `a * n_s`. Per-step
inputs that belong to a trace (continuation, importance ratio, given target policy) come per class,
numbered block by block.

Time indices as everywhere: `x_t, a_t, r_tp1, z_tp1, gamma_t, gamma_tp1, x_tp1`. Per demon d of class c:
    delta_t = r_tp1 + (1 - gamma_tp1) z_tp1 + gamma_tp1 theta . x_bar_tp1 - theta . x_t
    e_t     = s_t x_t + gamma_t lambda rho_t e_{t-1}     (s_t = rho_t for TD/GTD, 1 for GQ)
    theta  += alpha   (delta_t e_t - gamma_tp1 (1 - lambda) (w . e_t) x_bar_tp1)    (no correction for TD)
    w      += alpha_w (delta_t e_t - (w . x_t) x_t)                                 (GTD and GQ)
The step sizes are used as given (divide by the number of active features before building a block).
"""

from __future__ import annotations

from collections.abc import Hashable, Sequence
from dataclasses import dataclass, field
from typing import Literal, NamedTuple

import numpy as np

from horde.core.policies import EPSILON_GREEDY, FIXED, GREEDY, SOFTMAX, value_policy

A = 4  # actions of GQ blocks
TRACE_CUT = 1e-8  # trace entries below this are set to zero (DESIGN section 6)

Learner = Literal["td", "gtd", "gq"]
BlockPolicy = Literal["given", "greedy", "softmax", "epsilon_greedy"]
LEARNER_CODES = {"td": 0, "gtd": 1, "gq": 2}
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
            if classes[0] != 0 or not np.isin(np.diff(classes), (0, 1)).all():
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
        dtype: of the weights and traces (float64 by default; float32 halves the memory traffic).
        cut: the trace cut (0 keeps every non-zero entry).
    """

    blocks: tuple[Block, ...]
    num_features: int
    active: int
    dtype: np.dtype = field(default=np.dtype(np.float64))
    cut: float = TRACE_CUT

    def __post_init__(self) -> None:
        object.__setattr__(self, "blocks", tuple(self.blocks))
        object.__setattr__(self, "dtype", np.dtype(self.dtype))
        if self.dtype not in (np.float32, np.float64):
            raise ValueError(f"dtype must be float32 or float64, not {self.dtype}")
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
    def lo(self) -> np.ndarray:
        """[B] first demon of each block."""
        return np.cumsum([0] + [b.size for b in self.blocks])[:-1]

    @property
    def hi(self) -> np.ndarray:
        """[B] one past the last demon of each block."""
        return np.cumsum([b.size for b in self.blocks])

    @property
    def class_lo(self) -> np.ndarray:
        """[B] first trace class of each block."""
        return np.cumsum([0] + [b.num_classes for b in self.blocks])[:-1]

    def demon_class(self) -> np.ndarray:
        """[D] the global trace class of every demon."""
        return np.concatenate([c + b.classes for c, b in zip(self.class_lo, self.blocks, strict=True)])

    def rows(self, block: Block) -> int:
        """Rows of a block's weights: A * n_s for GQ, n_s otherwise."""
        return self.num_features * (A if block.learner == "gq" else 1)

    def weight_bytes(self) -> int:
        """Bytes of theta and w of every demon."""
        return 2 * sum(self.rows(b) * b.size for b in self.blocks) * self.dtype.itemsize


class ScaleState(NamedTuple):
    """Everything that changes while the blocks learn."""

    theta: tuple[np.ndarray, ...]  # per block [n_b, Db] primary weights, feature-major
    w: tuple[np.ndarray, ...]  # per block [n_b, Db] secondary weights
    e: tuple[np.ndarray, ...]  # per block [n_b, C_b] one trace per class, zero off the support
    x: np.ndarray  # [k] active state features at s_t
    gamma: np.ndarray  # [C] continuation of each class at s_t
    q: np.ndarray  # [D, A] values at s_t: action values (GQ) or the state value in column 0
    pi: np.ndarray  # [D, A] target policy at s_t (GQ; uniform for TD/GTD)
    prediction: np.ndarray  # [D] prediction at s_t


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
    """The one shape check where arrays enter the scale engine."""
    if array.shape != shape:
        raise ValueError(f"{name} has shape {array.shape}, expected {shape}")


def zeros(layout: Layout) -> ScaleState:
    """All weights and traces zero, nothing observed yet (call `observe`)."""
    dt = layout.dtype
    d = layout.num_demons
    return ScaleState(
        theta=tuple(np.zeros((layout.rows(b), b.size), dt) for b in layout.blocks),
        w=tuple(np.zeros((layout.rows(b), b.size), dt) for b in layout.blocks),
        e=tuple(np.zeros((layout.rows(b), b.num_classes), dt) for b in layout.blocks),
        x=np.zeros(layout.active, dtype=np.int64),
        gamma=np.zeros(layout.num_classes),
        q=np.zeros((d, A)),
        pi=np.full((d, A), 1.0 / A),
        prediction=np.zeros(d),
    )


def _own_policy(block: Block, q: np.ndarray) -> np.ndarray:
    """[Db, A] probabilities of an own-value block's demons."""
    kind = np.full(block.size, POLICY_CODES[block.policy])
    assert block.temperature is not None and block.epsilon is not None
    return value_policy(q, kind, block.temperature, block.epsilon)


def _values(layout: Layout, block: Block, theta: np.ndarray, x: np.ndarray) -> np.ndarray:
    """[Db, A] action values (GQ) or [Db, 1] state values at active features x, summed in float64."""
    if block.learner == "gq":
        rows = np.arange(A)[:, None] * layout.num_features + x[None, :]  # [A, k]
        return theta[rows].sum(axis=1, dtype=np.float64).T  # [Db, A]
    return theta[x].sum(axis=0, dtype=np.float64)[:, None]  # [Db, 1]


def _target(layout: Layout, b: int, values: np.ndarray, pi: np.ndarray | None) -> np.ndarray:
    """[Db, A] the target policy of block b's demons: own-value, or the given one of their class."""
    block = layout.blocks[b]
    if block.policy != "given":
        return _own_policy(block, values)
    if pi is None:
        return np.full((block.size, A), 1.0 / A)
    assert block.classes is not None
    return np.asarray(pi, dtype=float)[layout.class_lo[b] + block.classes]


def observe(layout: Layout, state: ScaleState, x: np.ndarray, pi: np.ndarray | None = None) -> ScaleState:
    """A stream (or episode) starts at a state with active features x: traces to zero, values read.

    Args:
        layout: the blocks.
        state: the weights to keep.
        x: [k] active state features.
        pi: [C, A] the given target policy of each class at this state (read by given-policy GQ
            demons for their prediction; uniform if None).
    """
    x = np.asarray(x, dtype=np.int64)
    _check("x", x, (layout.active,))
    q, policy, prediction = state.q.copy(), state.pi.copy(), state.prediction.copy()
    for b, (block, lo, hi, theta) in enumerate(zip(layout.blocks, layout.lo, layout.hi, state.theta, strict=True)):
        values = _values(layout, block, theta, x)  # [Db, A] or [Db, 1]
        q[lo:hi, : values.shape[1]] = values
        if block.learner != "gq":
            prediction[lo:hi] = values[:, 0]
            continue
        policy[lo:hi] = _target(layout, b, values, pi)
        prediction[lo:hi] = (policy[lo:hi] * values).sum(axis=1)
    return state._replace(
        e=tuple(np.zeros_like(e) for e in state.e),
        x=x,
        gamma=np.zeros(layout.num_classes),
        q=q,
        pi=policy,
        prediction=prediction,
    )


def step(
    layout: Layout,
    state: ScaleState,
    action: int,
    b_prob: float,
    x_tp1: np.ndarray,
    r_tp1: np.ndarray,
    z_tp1: np.ndarray,
    gamma_tp1: np.ndarray,
    rho_t: np.ndarray | None = None,
    pi_tp1: np.ndarray | None = None,
) -> tuple[ScaleState, np.ndarray]:
    """One transition (s_t, a_t) -> s_{t+1} for every demon of every block.

    Args:
        layout: the blocks.
        state: the blocks at s_t (its `x` holds x_t).
        action: a_t.
        b_prob: b(a_t | s_t), for the importance ratios of own-value demons.
        x_tp1: [k] active state features at s_{t+1}.
        r_tp1, z_tp1: [D] cumulants and outcomes.
        gamma_tp1: [C] continuation of each trace class at s_{t+1} (own-value demons: one class each).
        rho_t: [C] pi(a_t | s_t) / b(a_t | s_t) of each given-policy class (own-value entries are
            ignored; None: all 1, on-policy).
        pi_tp1: [C, A] the given target policy at s_{t+1} of each class (read by given-policy GQ demons;
            None: uniform).

    Returns:
        (new state, delta_t [D]).
    """
    d, nc = layout.num_demons, layout.num_classes
    x_tp1 = np.asarray(x_tp1, dtype=np.int64)
    gamma_tp1 = np.asarray(gamma_tp1, dtype=float)
    rho_t = np.ones(nc) if rho_t is None else np.asarray(rho_t, dtype=float)
    _check("x_tp1", x_tp1, (layout.active,))
    for name, array, shape in (
        ("r_tp1", r_tp1, (d,)),
        ("z_tp1", z_tp1, (d,)),
        ("gamma_tp1", gamma_tp1, (nc,)),
        ("rho_t", rho_t, (nc,)),
    ):
        _check(name, np.asarray(array), shape)
    if pi_tp1 is not None:
        _check("pi_tp1", np.asarray(pi_tp1), (nc, A))
    n_s = layout.num_features
    delta = np.zeros(d)
    gamma = state.gamma.copy()
    q, pi, prediction = state.q.copy(), state.pi.copy(), state.prediction.copy()
    thetas, ws, es = [], [], []
    for b, block in enumerate(layout.blocks):
        lo, hi = int(layout.lo[b]), int(layout.hi[b])
        cls = slice(int(layout.class_lo[b]), int(layout.class_lo[b]) + block.num_classes)
        members = block.classes  # [Db] class of each demon within the block
        gq, td = block.learner == "gq", block.learner == "td"
        theta, w = state.theta[b].copy(), state.w[b].copy()
        g1 = gamma_tp1[cls][members]  # [Db]
        rows_t = state.x + action * n_s if gq else state.x  # [k] rows of x_t
        # Values at s_{t+1} under the weights before this update; the target policy there.
        values_old = _values(layout, block, theta, x_tp1)  # [Db, A] or [Db, 1]
        if gq:
            pi_next = _target(layout, b, values_old, pi_tp1)  # [Db, A]
            v_next = (pi_next * values_old).sum(axis=1)  # [Db]
            v_t = state.q[lo:hi, action]  # [Db] theta . x_t
        else:
            v_next = values_old[:, 0]
            v_t = state.q[lo:hi, 0]
        delta_b = r_tp1[lo:hi] + (1.0 - g1) * z_tp1[lo:hi] + g1 * v_next - v_t  # [Db]
        # One trace per class: decay gamma_t lambda rho_t, plus rho_t x_t (TD/GTD) or x_t (GQ).
        rho = state.pi[lo:hi, action] / b_prob if block.policy != "given" else rho_t[cls]  # [C_b]
        e = state.e[b] * (state.gamma[cls] * block.lam * rho)[None, :]  # [n_b, C_b] in float64, a fresh array
        e[rows_t] += 1.0 if gq else rho[None, :]
        e[np.abs(e) < layout.cut] = 0.0
        e = e.astype(layout.dtype, copy=False)  # traces are stored, and used, in the layout's dtype
        support = np.flatnonzero((e != 0.0).any(axis=1))  # [nnz] rows of the trace
        ev = e[support][:, members].astype(np.float64)  # [nnz, Db] each demon's trace on the support
        if not td:
            w_dot_e = (w[support] * ev).sum(axis=0)  # [Db]
            w_dot_x = w[rows_t].sum(axis=0, dtype=np.float64)  # [Db]
        theta[support] += ev * (block.alpha * delta_b)[None, :]
        if not td:
            w[support] += ev * (block.alpha_w * delta_b)[None, :]
            correction = block.alpha * g1 * (1.0 - block.lam) * w_dot_e  # [Db]
            if gq:
                rows_next = np.arange(A)[:, None] * n_s + x_tp1[None, :]  # [A, k]
                theta[rows_next] -= correction[None, None, :] * pi_next.T[:, None, :]
            else:
                theta[x_tp1] -= correction[None, :]
            w[rows_t] -= (block.alpha_w * w_dot_x)[None, :]
        # Observe s_{t+1} under the new weights.
        values = _values(layout, block, theta, x_tp1)
        q[lo:hi, : values.shape[1]] = values
        if gq:
            pi[lo:hi] = _target(layout, b, values, pi_tp1)
            prediction[lo:hi] = (pi[lo:hi] * values).sum(axis=1)
        else:
            prediction[lo:hi] = values[:, 0]
        delta[lo:hi] = delta_b
        gamma[cls] = gamma_tp1[cls]
        thetas.append(theta)
        ws.append(w)
        es.append(e)
    return ScaleState(tuple(thetas), tuple(ws), tuple(es), x_tp1, gamma, q, pi, prediction), delta


def demon_arrays(layout: Layout, state: ScaleState, demon: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One demon's (theta, w, e), each [n_b] (copies): the demon-major view the small-world engine uses."""
    b = int(np.searchsorted(layout.hi, demon, side="right"))
    row = demon - int(layout.lo[b])
    block = layout.blocks[b]
    assert block.classes is not None
    column = int(block.classes[row])
    return state.theta[b][:, row].copy(), state.w[b][:, row].copy(), state.e[b][:, column].copy()
