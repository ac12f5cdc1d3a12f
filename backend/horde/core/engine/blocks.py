"""Blocks of demons and their trace classes: how `horde.py` lays out a run's demons for the engine (DESIGN section 6).

* **Stacked weights, feature-major.** A block's weights are one array `[n, Db]`: the weights of one feature
  for all demons of the block are contiguous, so a trace entry `e[j]` updates one contiguous run
  `theta[j, :] += alpha * delta * e[j]`, and the sums `theta . x` over the active features read whole rows.
* **Shared traces.** Demons with the same features, target policy, continuation and lambda have the same
  eligibility trace: rho and the decay `gamma_t * lambda * rho_t` are the same for all of them, and so is
  `x_t` (a dutch trace also holds alpha: only demons of one alpha share one). Such demons form a *trace
  class* (consecutive demons of a block) with one trace column. Demons that follow their own action values
  (control demons) have rho of their own: each is its own class.
* **Sparse traces, cut.** After each step, trace entries below `cut` in magnitude are set to zero
  (`engine.traces`); `cut = 0` keeps every non-zero entry and equals `reference.py` to 1e-9; the default
  `TRACE_CUT = 1e-8` is measured against the reference in tests/core/test_engine_vs_reference.py.
"""

from __future__ import annotations

from collections.abc import Hashable, Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np

from horde.core.learners import Kernel, kernel_for
from horde.core.policies import EPSILON_GREEDY, FIXED, GREEDY, SOFTMAX

TRACE_CUT = 1e-8  # trace entries below this are set to zero (DESIGN section 6)
BlockPolicy = Literal["given", "greedy", "softmax", "epsilon_greedy"]
POLICY_CODES = {"given": FIXED, "greedy": GREEDY, "softmax": SOFTMAX, "epsilon_greedy": EPSILON_GREEDY}


@dataclass(frozen=True)
class Block:
    """Demons that share one feature set, one learner (and step-size mode) and one lambda; their traces share
    one support.

    Args:
        learner: a declared learner ("gq" learns action values over A x n_s state-action features).
        alpha: [Db] step sizes of theta, as used in the update (divided by the active count).
        alpha_w: [Db] step sizes of the secondary weights (tdrc: of h; ignored by TD).
        lam: the block's lambda.
        policy: "given" (target policies supplied per trace class) or a policy over each demon's own action
            values (action-value learners only; every demon is its own class).
        classes: [Db] trace class of each demon of a given-policy block: 0, 1, 2, ... non-decreasing
            (demons of a class are consecutive). Default: one class, one shared trace.
        temperature, epsilon: [Db] of softmax / epsilon-greedy policies (default 1 and 0.1).
        step_size: "constant", or "autostep" / "tidbd": per-weight step sizes starting at alpha.
        meta: [Db] the meta step sizes of those.
        beta: [Db] tdrc's regulariser of h (default 0).
    """

    learner: str
    alpha: np.ndarray
    alpha_w: np.ndarray
    lam: float
    policy: BlockPolicy = "given"
    classes: np.ndarray | None = None
    temperature: np.ndarray | None = None
    epsilon: np.ndarray | None = None
    step_size: str = "constant"
    meta: np.ndarray | None = None
    beta: np.ndarray | None = None

    @property
    def kernel(self) -> Kernel:
        """The engine's kernel for the block's learner and step-size mode."""
        return kernel_for(self.learner, self.step_size)

    @property
    def code(self) -> int:
        """The kernel's code in the compiled step."""
        return self.kernel.code

    def __post_init__(self) -> None:
        alpha = np.asarray(self.alpha, dtype=float).ravel()
        object.__setattr__(self, "alpha", alpha)
        for name, default in (("alpha_w", None), ("temperature", 1.0), ("epsilon", 0.1), ("meta", 0.0),
                              ("beta", 0.0)):  # fmt: skip
            value = getattr(self, name)
            value = np.full(alpha.shape, default) if value is None else np.asarray(value, dtype=float)
            _check(name, value, alpha.shape)
            object.__setattr__(self, name, value)
        if self.policy not in POLICY_CODES:
            raise ValueError(f"unknown policy {self.policy!r}")
        self.kernel  # noqa: B018 (raises for a learner and step size no kernel learns)
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
