"""The blocks of the one engine (`engine/blocks.py`): trace classes, and what a block refuses.

The learning of blocks is held equal to `reference.py` through the simulation itself
(tests/core/test_engine_vs_reference.py, with shared traces, the cut at 0 and at its default).
"""

from __future__ import annotations

import numpy as np
import pytest

from horde.core.engine import blocks
from horde.core.engine.blocks import Block


def test_trace_classes_group_demons_with_the_same_trace() -> None:
    keys = [("pi1", 0.9, 0.8), ("pi2", 0.9, 0.8), ("pi1", 0.9, 0.8), ("pi1", 0.5, 0.8), ("pi2", 0.9, 0.8)]
    order, classes = blocks.trace_classes(keys)
    assert order.tolist() == [0, 2, 1, 4, 3]
    assert classes.tolist() == [0, 0, 1, 1, 2]
    block = Block("gtd", np.full(5, 0.1), np.full(5, 0.01), 0.8, classes=classes)  # a valid class numbering
    assert block.classes.tolist() == [0, 0, 1, 1, 2] and block.num_classes == 3 and block.size == 5
    assert block.kernel.learner == "gtd" and block.kernel.owes  # the engine's kernel for it


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"learner": "gtd", "policy": "softmax"}, "needs action values"),
        ({"learner": "gq", "policy": "softmax", "classes": np.array([0, 1])}, "own trace class"),
        ({"learner": "gtd", "classes": np.array([0, 2])}, "numbered 0, 1, 2"),
        ({"learner": "gtd", "classes": np.array([1, 1])}, "numbered 0, 1, 2"),
    ],
)
def test_blocks_reject_what_they_cannot_learn(kwargs: dict, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        Block(alpha=np.full(2, 0.1), alpha_w=np.full(2, 0.01), lam=0.9, **kwargs)
