"""What a block's demons say at a state, from their values there: target policies, action values, predictions.

A demon's target policy is given per trace class (uniform, fixed, another demon's, a sign rule:
`Classes.pi_given`) or, for a control demon (GQ), greedy / softmax / epsilon-greedy over its own action values
(`value_policy`, the compiled `policies.value_policy`). Its prediction is its value (state values) or
sum_a pi(a) q(a) (action values).
"""

from __future__ import annotations

import math

from numba import njit

from horde.core.engine.layout import NO_NRT
from horde.core.engine.rows import at, read_range
from horde.core.policies import EPSILON_GREEDY, FIXED, SOFTMAX, TIE_TOLERANCE


@njit(**NO_NRT)
def value_policy(kind, q, temperature, epsilon, out):
    """out[:A] = greedy / softmax / epsilon-greedy probabilities over action values q[:A] (policies.py)."""
    A = out.shape[0]  # the world's number of actions, from the arrays (four in the grid world)
    best = q[0]
    for a in range(1, A):
        best = max(best, q[a])
    if kind == SOFTMAX:
        zmax = q[0] / temperature
        for a in range(1, A):
            zmax = max(zmax, q[a] / temperature)
        total = 0.0
        for a in range(A):
            out[a] = math.exp(q[a] / temperature - zmax)
            total += out[a]
        for a in range(A):
            out[a] = out[a] / total
        return
    count = 0
    for a in range(A):
        if q[a] >= best - TIE_TOLERANCE:
            count += 1
    for a in range(A):
        greedy = (1.0 if q[a] >= best - TIE_TOLERANCE else 0.0) / count
        out[a] = epsilon / A + (1.0 - epsilon) * greedy if kind == EPSILON_GREEDY else greedy


@njit(**NO_NRT)
def target(b, i, lay, cls, values, out):
    """out[:A] = the target policy of block b's demon i at the state whose values are values[:, i]."""
    d = lay.block_lo[b] + i
    if lay.policy[b] == FIXED:
        c = lay.slot_class[d]
        for a in range(out.shape[0]):
            out[a] = cls.pi_given[c, a]
        return
    value_policy(lay.policy[b], values[:, i], lay.temperature[d], lay.epsilon[d], out)


@njit(**NO_NRT)
def observe_range(b, i0, i1, lay, dem, cls, values):
    """Store the values, policies and predictions of block b's demons i0 <= i < i1 at a state (their values
    there in values[:, i])."""
    lo = lay.block_lo[b]
    A = dem.q.shape[1]
    if lay.actions[b] == 1:  # state values (unsigned offsets: the loop vectorizes, `rows.at`)
        q_0, value = dem.q[:, 0], values[0]
        for i in range(i0, i1):
            u, d = at(i), at(lo + i)
            q_0[d] = value[u]
            dem.pred[d] = value[u]
        return
    for i in range(i0, i1):
        d = lo + i
        target(b, i, lay, cls, values, dem.pi[d])
        total = 0.0
        for a in range(A):
            dem.q[d, a] = values[a, i]
            total += dem.pi[d, a] * values[a, i]
        dem.pred[d] = total


@njit(**NO_NRT)
def read_and_observe(b, lay, wts, dem, cls, scr, x, v, n_s):
    """Block b's values at the state with active features (x, v), then its demons' policies and predictions."""
    db = lay.block_hi[b] - lay.block_lo[b]
    read_range(lay.woff[b], db, lay.actions[b], n_s, wts.theta, x, v, 0, db, scr.values)
    observe_range(b, 0, db, lay, dem, cls, scr.values)
