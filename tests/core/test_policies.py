"""Target and behaviour policies (DESIGN section 4): exact probabilities, and sampling from them."""

from __future__ import annotations

import numpy as np
import pytest

from horde.core import reference
from horde.core.policies import (
    EPSILON_GREEDY,
    GREEDY,
    SOFTMAX,
    epsilon_greedy,
    greedy,
    sample,
    softmax,
    value_policy,
)


def test_greedy_puts_all_mass_on_the_best_action():
    assert greedy(np.array([0.0, 2.0, 1.0, -1.0])).tolist() == [0, 1, 0, 0]


def test_greedy_splits_ties_evenly():
    assert greedy(np.array([1.0, 3.0, 3.0, 0.0])).tolist() == [0, 0.5, 0.5, 0]
    assert greedy(np.zeros(4)).tolist() == [0.25] * 4
    assert greedy(np.array([5.0, 5.0, 5.0, 4.0])).tolist() == pytest.approx([1 / 3, 1 / 3, 1 / 3, 0])
    # values equal up to rounding count as tied
    assert greedy(np.array([0.1 + 0.2, 0.3, 0.0, 0.0])).tolist() == [0.5, 0.5, 0, 0]


def test_greedy_works_on_stacks():
    q = np.array([[[1.0, 0, 0, 0], [0, 0, 2, 2]], [[0, 0, 0, 0], [-1, -2, -3, -4]]])  # [B=2, D=2, A]
    np.testing.assert_array_equal(
        greedy(q), [[[1, 0, 0, 0], [0, 0, 0.5, 0.5]], [[0.25, 0.25, 0.25, 0.25], [1, 0, 0, 0]]]
    )


def test_softmax_matches_the_hand_computation():
    q = np.array([1.0, 2.0, 0.0, -1.0])
    # T = 1: exp(q) = 2.718281828, 7.389056099, 1, 0.367879441; sum 11.475217368
    np.testing.assert_allclose(softmax(q, 1.0), [0.236882818, 0.643914260, 0.087144319, 0.032058603], atol=1e-9)
    # T = 2: exp(q / 2) = 1.648721271, 2.718281828, 1, 0.606530660; sum 5.973533759
    np.testing.assert_allclose(softmax(q, 2.0), [0.276004345, 0.455054234, 0.167405097, 0.101536324], atol=1e-9)


def test_softmax_temperature_limits_and_shift_invariance():
    q = np.array([1.0, 2.0, 0.0, -1.0])
    np.testing.assert_allclose(softmax(q, 1e6), [0.25] * 4, atol=1e-5)
    np.testing.assert_allclose(softmax(q, 1e-3), [0, 1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(softmax(q + 1000.0, 1.0), softmax(q, 1.0), atol=1e-12)  # no overflow
    assert np.isfinite(softmax(np.array([1e4, 0.0, 0.0, 0.0]), 0.01)).all()


def test_softmax_per_demon_temperatures():
    q = np.array([[1.0, 2.0, 0.0, -1.0], [1.0, 2.0, 0.0, -1.0]])
    out = softmax(q, np.array([1.0, 2.0]))
    np.testing.assert_allclose(out[0], softmax(q[0], 1.0))
    np.testing.assert_allclose(out[1], softmax(q[1], 2.0))


def test_epsilon_greedy():
    # epsilon / 4 = 0.05 everywhere, plus 0.8 on the greedy action (split on ties)
    np.testing.assert_allclose(epsilon_greedy(np.array([0.0, 5.0, 1.0, 2.0]), 0.2), [0.05, 0.85, 0.05, 0.05])
    np.testing.assert_allclose(epsilon_greedy(np.array([5.0, 5.0, 1.0, 2.0]), 0.2), [0.45, 0.45, 0.05, 0.05])
    np.testing.assert_allclose(epsilon_greedy(np.array([0.0, 5.0, 1.0, 2.0]), 1.0), [0.25] * 4)
    np.testing.assert_allclose(epsilon_greedy(np.array([0.0, 5.0, 1.0, 2.0]), 0.0), [0, 1, 0, 0])


def test_value_policy_gives_each_demon_its_own_kind():
    q = np.array([[1.0, 2.0, 0.0, -1.0]] * 3)  # [D=3, A]
    kind = np.array([GREEDY, SOFTMAX, EPSILON_GREEDY])
    out = value_policy(q, kind, np.array([1.0, 2.0, 1.0]), np.array([0.1, 0.1, 0.4]))
    np.testing.assert_allclose(out[0], [0, 1, 0, 0])
    np.testing.assert_allclose(out[1], softmax(q[1], 2.0))
    np.testing.assert_allclose(out[2], [0.1, 0.7, 0.1, 0.1])
    # with a batch axis in front
    batch = value_policy(np.stack([q, -q]), kind, np.array([1.0, 2.0, 1.0]), np.array([0.1, 0.1, 0.4]))
    np.testing.assert_allclose(batch[0], out)
    np.testing.assert_allclose(batch[1, 0], [0, 0, 0, 1])


@pytest.mark.parametrize("kind", ["greedy", "softmax", "epsilon_greedy"])
def test_value_policy_equals_the_plain_reference(kind):
    rng = np.random.default_rng(0)
    code = {"greedy": GREEDY, "softmax": SOFTMAX, "epsilon_greedy": EPSILON_GREEDY}[kind]
    for _ in range(50):
        q = np.round(rng.normal(size=4), 1)  # rounding makes ties common
        t, e = rng.uniform(0.1, 3), rng.uniform(0, 1)
        ours = value_policy(q[None], np.array([code]), np.array([t]), np.array([e]))[0]
        np.testing.assert_allclose(ours, reference.value_policy(kind, q, t, e), atol=1e-12)


def test_sample_frequencies_follow_the_probabilities():
    n = 100_000
    probs = np.tile([0.1, 0.2, 0.3, 0.4], (n, 1))
    actions = sample(probs, np.random.default_rng(1))
    assert actions.dtype == np.int64 and actions.shape == (n,)
    freq = np.bincount(actions, minlength=4) / n
    for f, p in zip(freq, [0.1, 0.2, 0.3, 0.4], strict=True):
        assert abs(f - p) < 4 * np.sqrt(p * (1 - p) / n)


def test_sample_never_draws_an_impossible_action():
    n = 20_000
    probs = np.tile([0.0, 0.5, 0.0, 0.5], (n, 1))
    actions = sample(probs, np.random.default_rng(2))
    assert set(np.unique(actions).tolist()) == {1, 3}
    assert sample(np.tile([0.0, 0.0, 0.0, 1.0], (100, 1)), np.random.default_rng(0)).tolist() == [3] * 100
    assert sample(np.tile([1.0, 0.0, 0.0, 0.0], (100, 1)), np.random.default_rng(0)).tolist() == [0] * 100


def test_sample_rows_are_independent_and_seeded():
    probs = np.array([[1.0, 0, 0, 0], [0, 0, 1.0, 0], [0.25, 0.25, 0.25, 0.25]])
    a = sample(np.repeat(probs, 1000, axis=0), np.random.default_rng(3))
    b = sample(np.repeat(probs, 1000, axis=0), np.random.default_rng(3))
    np.testing.assert_array_equal(a, b)
    assert (a[:1000] == 0).all() and (a[1000:2000] == 2).all()
    assert len(np.unique(a[2000:])) == 4
