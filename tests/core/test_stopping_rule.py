"""The protocol's stopping rule, the one function that `run_trial` and a live run both use."""

from __future__ import annotations

import numpy as np

from horde.core.experiment import stopping_rule
from horde.spec import StopRule

RULE = StopRule(window=2, tolerance=0.1)


def test_between_windows_the_weights_are_not_even_read() -> None:
    reference = [np.zeros(2)]

    def unread() -> list[np.ndarray]:
        raise AssertionError("the weights were copied between two windows")

    assert stopping_rule(RULE, 3, unread, reference) == (False, reference)
    assert stopping_rule(None, 2, unread, reference) == (False, reference)


def test_a_window_that_moved_no_weight_by_the_tolerance_stops_the_trial() -> None:
    reference = [np.array([1.0, 2.0]), np.array([0.5])]
    moved = [np.array([1.05, 1.95]), np.array([0.45])]  # largest change 0.05 < 0.1
    stopped, kept = stopping_rule(RULE, 4, lambda: moved, reference)
    assert stopped and kept is reference


def test_a_window_that_moved_one_weight_by_the_tolerance_goes_on_from_the_new_weights() -> None:
    reference = [np.array([1.0, 2.0]), np.array([0.5])]
    moved = [np.array([1.0, 2.0]), np.array([0.75])]  # 0.25 >= the tolerance of 0.1
    stopped, kept = stopping_rule(RULE, 2, lambda: moved, reference)
    assert not stopped and kept is moved
