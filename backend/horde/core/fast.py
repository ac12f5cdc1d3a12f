"""Compiled kernels (numba) for one agent's whole loop: world, features, questions, policies, learning.

The numpy engine (`world.py`, `horde.py`, `learners.py`) spends a few microseconds per array call,
and a thesis-scale step needs a couple of hundred of them. Here the same equations run as one compiled
loop over many steps, on flat arrays packed from the compiled `Horde`. The numpy engine stays the
readable reference: tests run both on the same seed and require equal weights and predictions (to
1e-9) and the same trajectory, since both draw the same numbers from the same generator in the same
order.

Weights of all groups live in one flat buffer per kind (theta, w, e, RUPEE's h and delta_e); the row of
slot s (demons sorted by group) starts at `group offset + (s - first slot) * n`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from horde.core import learners, metrics
from horde.core.horde import Horde, HordeState
from horde.core.policies import EPSILON_GREEDY, FIXED, GREEDY, KIND_CODES, OF, SOFTMAX, TIE_TOLERANCE, UNIFORM
from horde.core.world import DIRECTIONS, NUM_ACTIONS, PERPENDICULAR, World, WorldState
from horde.spec import BehaviourSpec

A = NUM_ACTIONS
FEATURE_KINDS = {"stripes": 0, "tiles": 1, "grid": 2, "constant": 3}

# Columns of the per-group integer table.
G_STAGE, G_ACTION_VALUES, G_NS, G_N, G_K, G_KIND, G_PARTS, G_TILINGS, G_TILES, G_BASE_N = range(10)
G_COND, G_THR_LO, G_THR_HI, G_SLOT_LO, G_SLOT_HI, G_OFFSET = range(10, 16)
# Columns of the per-slot tables.
S_DEMON, S_GROUP, S_POLICY, S_OF, S_RESET = range(5)
SF_LAM, SF_ALPHA, SF_ALPHA_W, SF_RHO_IN_TRACE, SF_CORRECT, SF_TEMPERATURE, SF_EPSILON, SF_DISCOUNT = range(8)
# World parameters.
W_WIDTH, W_HEIGHT, W_STEP, W_SLIP, W_NOISE, W_TRANSIENT, W_MAX_STEPS, W_START_RECT = range(8)
W_SX0, W_SY0, W_SX1, W_SY1 = range(8, 12)
# Node kinds (questions.NODE_KINDS).
N_CONST, N_SENSOR, N_PREDICTION, N_ADD, N_MUL, N_MIN, N_MAX, N_IF = range(8)
# Result fields of `_run`.
R_STEPS, R_EPISODES, R_ACTION, R_REWARD, R_TERMINATED, R_TRUNCATED, R_SIGN = range(7)


# ----------------------------------------------------------------------------------------------
# World


@njit(cache=True)
def _holds(rects, r, x, y):
    """Region r's rectangle holds (x, y): x0 <= x < x1 and y0 <= y < y1."""
    return rects[r, 0] <= x and x < rects[r, 2] and rects[r, 1] <= y and y < rects[r, 3]


@njit(cache=True)
def _inside(wp, rects, x, y, out):
    for r in range(rects.shape[0]):
        out[r] = _holds(rects, r, x, y)


@njit(cache=True)
def _blocked(wp, rects, is_obstacle, x, y):
    if x < 0.0 or x >= wp[W_WIDTH] or y < 0.0 or y >= wp[W_HEIGHT]:
        return True
    for r in range(rects.shape[0]):  # noqa: SIM110 (numba compiles loops, not any() over generators)
        if is_obstacle[r] and _holds(rects, r, x, y):
            return True
    return False


@njit(cache=True)
def _is_start_bad(wp, rects, is_obstacle, is_terminal, x, y):
    if _blocked(wp, rects, is_obstacle, x, y):
        return True
    for r in range(rects.shape[0]):  # noqa: SIM110 (numba compiles loops, not any() over generators)
        if is_terminal[r] and _holds(rects, r, x, y):
            return True
    return False


@njit(cache=True)
def _world_reset(rng, wp, rects, is_obstacle, is_terminal, color_cdf, color_count, pos, wsteps, colors):
    if wp[W_START_RECT] > 0.0:
        for _ in range(1000):
            pos[0] = wp[W_SX0] + (wp[W_SX1] - wp[W_SX0]) * rng.random()
            pos[1] = wp[W_SY0] + (wp[W_SY1] - wp[W_SY0]) * rng.random()
            if not _is_start_bad(wp, rects, is_obstacle, is_terminal, pos[0], pos[1]):
                break
    else:
        pos[0] = wp[W_SX0]
        pos[1] = wp[W_SY0]
    wsteps[0] = 0
    for i in range(color_count.shape[0]):
        u = rng.random()
        c = 0
        while c < color_count[i] and color_cdf[i, c] <= u:
            c += 1
        colors[i] = min(c, color_count[i] - 1)


@njit(cache=True)
def _terminal_reward(is_terminal, inside, term_reward, term_ind, term_table, colors):
    for r in range(inside.shape[0]):
        if inside[r] and is_terminal[r]:
            if term_ind[r] >= 0:
                return term_table[r, colors[term_ind[r]]]
            return term_reward[r]
    return 0.0


# ----------------------------------------------------------------------------------------------
# Features, values, policies


@njit(cache=True)
def _cell(u, parts):
    return min(max(math.floor(u * parts), 0), parts - 1)


@njit(cache=True)
def _features(gi, thresholds, g, x, y, condition, wp, out):
    """Active state features of group g at (x, y) into out[:k]."""
    kind = gi[g, G_KIND]
    u = x / wp[W_WIDTH]
    v = y / wp[W_HEIGHT]
    base_n = gi[g, G_BASE_N]
    if kind == 3:
        out[0] = 0
    elif kind == 2:
        tiles = gi[g, G_TILES]
        out[0] = _cell(u, tiles) * tiles + _cell(v, tiles)
    elif kind == 0:
        p = gi[g, G_PARTS]
        i = _cell(u, p)
        j = _cell(v, p)
        out[0] = i
        out[1] = p + j
        out[2] = 2 * p + (i + j)
        out[3] = 2 * p + (2 * p - 1) + (i - j + p - 1)
        out[4] = base_n - 1
    else:
        tilings = gi[g, G_TILINGS]
        tiles = gi[g, G_TILES]
        side = tiles + 1
        for t in range(tilings):
            ou = (t * 1 / tilings) % 1.0
            ov = (t * 3 / tilings) % 1.0
            i = min(max(math.floor(u * tiles + ou), 0), tiles)
            j = min(max(math.floor(v * tiles + ov), 0), tiles)
            out[t] = t * side * side + i * side + j
        out[tilings] = base_n - 1
    lo = gi[g, G_THR_LO]
    hi = gi[g, G_THR_HI]
    if hi > lo:
        block = 0
        for t in range(lo, hi):
            if condition >= thresholds[t]:
                block += 1
        for j in range(gi[g, G_K]):
            out[j] += block * base_n


@njit(cache=True)
def _values(gi, g, theta, row, idx, out):
    """Action values into out[:A] (or the state value into out[0]) of the demon whose row starts at `row`."""
    k = gi[g, G_K]
    if gi[g, G_ACTION_VALUES]:
        ns = gi[g, G_NS]
        for a in range(A):
            total = 0.0
            for j in range(k):
                total += theta[row + a * ns + idx[j]]
            out[a] = total
    else:
        total = 0.0
        for j in range(k):
            total += theta[row + idx[j]]
        out[0] = total


@njit(cache=True)
def _value_policy(kind, q, temperature, epsilon, out):
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


@njit(cache=True)
def _policy(si, sf, fixed, s, q, pi, out):
    kind = si[s, S_POLICY]
    if kind in (GREEDY, SOFTMAX, EPSILON_GREEDY):
        _value_policy(kind, q, sf[s, SF_TEMPERATURE], sf[s, SF_EPSILON], out)
    elif kind == OF:
        for a in range(A):
            out[a] = pi[si[s, S_OF], a]
    else:
        for a in range(A):
            out[a] = fixed[s, a]


@njit(cache=True)
def _prediction(action_values, pi_row, q):
    if not action_values:
        return q[0]
    total = 0.0
    for a in range(A):
        total += pi_row[a] * q[a]
    return total


@njit(cache=True)
def _behaviour(beh_i, beh_f, beh_probs, q, out):
    kind = beh_i[0]
    if kind == UNIFORM:
        for a in range(A):
            out[a] = 1.0 / A
    elif kind == FIXED:
        for a in range(A):
            out[a] = beh_probs[a]
    else:
        _value_policy(kind, q[beh_i[1]], beh_f[0], beh_f[1], out)


# ----------------------------------------------------------------------------------------------
# Questions


@njit(cache=True)
def _evaluate(lo, hi, node_kind, node_arg, node_start, node_children, sensors, pred, values):
    for n in range(lo, hi):
        kind = node_kind[n]
        if kind == N_CONST:
            values[n] = node_arg[n]
        elif kind == N_SENSOR:
            values[n] = sensors[int(node_arg[n])]
        elif kind == N_PREDICTION:
            values[n] = pred[int(node_arg[n])]
        elif kind == N_IF:
            c = node_children[node_start[n]]
            values[n] = (
                values[node_children[node_start[n] + 1]]
                if values[c] != 0.0
                else values[node_children[node_start[n] + 2]]
            )
        else:
            acc = values[node_children[node_start[n]]]
            for j in range(node_start[n] + 1, node_start[n + 1]):
                x = values[node_children[j]]
                if kind == N_ADD:
                    acc = acc + x
                elif kind == N_MUL:
                    acc = acc * x
                elif kind == N_MIN:
                    acc = min(acc, x)
                else:
                    acc = max(acc, x)
            values[n] = acc


# ----------------------------------------------------------------------------------------------
# The Horde


@njit(cache=True)
def _observe(gi, thresholds, si, sf, fixed, wp, x, y, theta, feat, pi, q, pred, scratch_q, scratch_pi):
    """Features, policies, values and predictions of every demon at (x, y), group by group."""
    for g in range(gi.shape[0]):
        cond = pred[gi[g, G_COND]] if gi[g, G_COND] >= 0 else 0.0
        _features(gi, thresholds, g, x, y, cond, wp, feat[g])
        n = gi[g, G_N]
        for s in range(gi[g, G_SLOT_LO], gi[g, G_SLOT_HI]):
            d = si[s, S_DEMON]
            row = gi[g, G_OFFSET] + (s - gi[g, G_SLOT_LO]) * n
            _values(gi, g, theta, row, feat[g], scratch_q)
            _policy(si, sf, fixed, s, scratch_q, pi, scratch_pi)
            for a in range(A):
                pi[d, a] = scratch_pi[a]
                q[d, a] = scratch_q[a] if gi[g, G_ACTION_VALUES] else np.nan
            pred[d] = _prediction(gi[g, G_ACTION_VALUES], scratch_pi, scratch_q)


@njit(cache=True)
def _start_episode(gi, thresholds, si, sf, fixed, wp, x, y, theta, w, e, feat, pi, q, pred, gamma, sq, spi):
    e[:] = 0.0
    for g in range(gi.shape[0]):
        n = gi[g, G_N]
        for s in range(gi[g, G_SLOT_LO], gi[g, G_SLOT_HI]):
            if si[s, S_RESET]:
                row = gi[g, G_OFFSET] + (s - gi[g, G_SLOT_LO]) * n
                theta[row : row + n] = 0.0
                w[row : row + n] = 0.0
    gamma[:] = 0.0
    _observe(gi, thresholds, si, sf, fixed, wp, x, y, theta, feat, pi, q, pred, sq, spi)


@njit(cache=True)
def _learn(
    gi, thresholds, si, sf, fixed, wp, stage_lo, stage_hi, node_kind, node_arg, node_start, node_children,
    out_r, out_z, out_g, action, b_prob, x, y, sensors, terminated, learning, with_metrics,
    theta, w, e, h, de, tau, dstats, feat, pi, q, pred, gamma, delta_out, cumulant, diverged,
    node_values, idx_tp1, q_old, pi_tp1, saved,
):  # fmt: skip
    """One transition for every demon, stage by stage (the equations of learners.update)."""
    current_stage = -1
    for g in range(gi.shape[0]):
        stage = gi[g, G_STAGE]
        if stage != current_stage:
            current_stage = stage
            _evaluate(stage_lo[stage], stage_hi[stage], node_kind, node_arg, node_start, node_children,
                      sensors, pred, node_values)  # fmt: skip
        k = gi[g, G_K]
        n = gi[g, G_N]
        ns = gi[g, G_NS]
        action_values = gi[g, G_ACTION_VALUES]
        cond = pred[gi[g, G_COND]] if gi[g, G_COND] >= 0 else 0.0
        _features(gi, thresholds, g, x, y, cond, wp, idx_tp1)
        shift = action * ns if action_values else 0
        if with_metrics:
            tau[g, 0] = (1 - metrics.RUPEE_BETA) * tau[g, 0] + metrics.RUPEE_BETA
            tau[g, 1] = (1 - metrics.UDE_BETA) * tau[g, 1] + metrics.UDE_BETA
        for s in range(gi[g, G_SLOT_LO], gi[g, G_SLOT_HI]):
            d = si[s, S_DEMON]
            row = gi[g, G_OFFSET] + (s - gi[g, G_SLOT_LO]) * n
            r = node_values[out_r[d]]
            z = node_values[out_z[d]]
            g1 = 0.0 if terminated else min(max(node_values[out_g[d]], 0.0), 1.0) * sf[s, SF_DISCOUNT]
            # pi(s_{t+1}) under the weights before this update
            _values(gi, g, theta, row, idx_tp1, q_old)
            _policy(si, sf, fixed, s, q_old, pi, pi_tp1)
            rho = pi[d, action] / b_prob
            lam = sf[s, SF_LAM]
            alpha = sf[s, SF_ALPHA]
            correct = sf[s, SF_CORRECT]
            v_t = 0.0
            for j in range(k):
                v_t += theta[row + shift + feat[g, j]]
            if action_values:
                v_bar = 0.0
                for a in range(A):
                    block = 0.0
                    for j in range(k):
                        block += theta[row + a * ns + idx_tp1[j]] * pi_tp1[a]
                    v_bar += block
            else:
                v_bar = 0.0
                for j in range(k):
                    v_bar += theta[row + idx_tp1[j]]
            delta = r + (1.0 - g1) * z + g1 * v_bar - v_t
            frozen = diverged[d] or not learning[d]
            if not frozen:
                saved[0, :n] = theta[row : row + n]
                saved[1, :n] = w[row : row + n]
                saved[2, :n] = e[row : row + n]
                trace_scale = rho if sf[s, SF_RHO_IN_TRACE] > 0.0 else 1.0
                decay = gamma[d] * lam * rho
                for i in range(row, row + n):
                    e[i] = e[i] * decay
                for j in range(k):
                    e[row + shift + feat[g, j]] += trace_scale
                w_dot_e = 0.0
                for i in range(row, row + n):
                    w_dot_e += w[i] * e[i]
                w_dot_x = 0.0
                for j in range(k):
                    w_dot_x += w[row + shift + feat[g, j]]
                c_theta = alpha * delta
                for i in range(row, row + n):
                    theta[i] += c_theta * e[i]
                correction = alpha * correct * g1 * (1.0 - lam) * w_dot_e
                if action_values:
                    for a in range(A):
                        for j in range(k):
                            theta[row + a * ns + idx_tp1[j]] -= correction * pi_tp1[a]
                else:
                    for j in range(k):
                        theta[row + idx_tp1[j]] -= correction
                step_w = sf[s, SF_ALPHA_W] * correct
                c_w = step_w * delta
                for i in range(row, row + n):
                    w[i] += c_w * e[i]
                c_wx = step_w * w_dot_x
                for j in range(k):
                    w[row + shift + feat[g, j]] -= c_wx
                finite = True
                for i in range(row, row + n):
                    if not (math.isfinite(theta[i]) and math.isfinite(w[i])):
                        finite = False
                        break
                if not finite:
                    diverged[d] = True
                    theta[row : row + n] = saved[0, :n]
                    w[row : row + n] = saved[1, :n]
                    e[row : row + n] = saved[2, :n]
            if with_metrics:
                alpha_h = metrics.RUPEE_ALPHA_H / k
                h_dot_x = 0.0
                for j in range(k):
                    h_dot_x += h[row + shift + feat[g, j]]
                c_h = alpha_h * delta
                for i in range(row, row + n):
                    h[i] += c_h * e[i]
                c_hx = alpha_h * h_dot_x
                for j in range(k):
                    h[row + shift + feat[g, j]] -= c_hx
                beta = metrics.RUPEE_BETA / tau[g, 0]
                c_de = beta * delta
                for i in range(row, row + n):
                    de[i] = (1 - beta) * de[i] + c_de * e[i]
                b = metrics.UDE_BETA / tau[g, 1]
                dstats[d, 0] = (1 - b) * dstats[d, 0] + b * delta
                dstats[d, 1] = (1 - b) * dstats[d, 1] + b * delta**2
                dstats[d, 2] = (1 - b) * dstats[d, 2] + b * abs(delta)
            # Observe s_{t+1} under the new weights.
            _values(gi, g, theta, row, idx_tp1, q_old)
            _policy(si, sf, fixed, s, q_old, pi, pi_tp1)
            for a in range(A):
                pi[d, a] = pi_tp1[a]
                if action_values:
                    q[d, a] = q_old[a]
            pred[d] = _prediction(action_values, pi_tp1, q_old)
            gamma[d] = g1
            delta_out[d] = delta
            cumulant[d] = r
        for j in range(k):
            feat[g, j] = idx_tp1[j]


@njit(cache=True, nogil=True)  # releases the GIL: the server's other threads go on while a run learns
def _run(
    max_steps, max_episodes, rng, result, returns,
    wp, rects, is_obstacle, is_terminal, term_reward, term_ind, term_table, ind_region, color_values, color_cdf,
    color_count, pos, wsteps, colors,
    beh_i, beh_f, beh_probs,
    gi, thresholds, si, sf, fixed, stage_lo, stage_hi, node_kind, node_arg, node_start, node_children,
    out_r, out_z, out_g, learning, with_metrics,
    theta, w, e, h, de, tau, dstats, feat, pi, q, pred, gamma, delta_out, cumulant, diverged,
):  # fmt: skip
    """Run steps until `max_steps` steps or `max_episodes` episode ends, starting new episodes as they end."""
    num_regions = rects.shape[0]
    num_indicators = ind_region.shape[0]
    sensors = np.zeros(6 + num_regions + num_indicators)
    inside = np.zeros(num_regions, dtype=np.bool_)
    b = np.zeros(A)
    cdf = np.zeros(A)
    kmax = feat.shape[1]
    idx_tp1 = np.zeros(kmax, dtype=np.int64)
    q_old = np.zeros(A)
    pi_tp1 = np.zeros(A)
    nmax = 1
    for g in range(gi.shape[0]):
        nmax = max(nmax, gi[g, G_N])
    saved = np.zeros((3, nmax))
    node_values = np.zeros(node_kind.shape[0])
    steps = 0
    episodes = 0
    while steps < max_steps and episodes < max_episodes:
        _behaviour(beh_i, beh_f, beh_probs, q, b)
        total = 0.0
        for a in range(A):
            total += b[a]
            cdf[a] = total
        u = rng.random() * cdf[A - 1]
        action = 0
        for a in range(A):
            if u >= cdf[a]:
                action += 1
        action = min(action, A - 1)
        moved = action
        if wp[W_SLIP] > 0.0:
            u2 = rng.random()
            if u2 < wp[W_SLIP]:
                moved = PERPENDICULAR_[action, 1 if u2 < wp[W_SLIP] / 2 else 0]
        dx = DIRECTIONS_[moved, 0] * wp[W_STEP]
        dy = DIRECTIONS_[moved, 1] * wp[W_STEP]
        if wp[W_NOISE] > 0.0:
            dx = dx + rng.normal(0.0, wp[W_NOISE])
            dy = dy + rng.normal(0.0, wp[W_NOISE])
        nx = pos[0] + dx
        ny = pos[1] + dy
        bump = 0.0
        if _blocked(wp, rects, is_obstacle, nx, ny):
            nx = pos[0]
            ny = pos[1]
            bump = 1.0
        _inside(wp, rects, nx, ny, inside)
        terminated = False
        for r in range(num_regions):
            if inside[r] and is_terminal[r]:
                terminated = True
        reward = wp[W_TRANSIENT]
        if terminated:
            reward = reward + _terminal_reward(is_terminal, inside, term_reward, term_ind, term_table, colors)
        wsteps[0] += 1
        truncated = wsteps[0] >= wp[W_MAX_STEPS] and not terminated
        pos[0] = nx
        pos[1] = ny
        sensors[0] = nx
        sensors[1] = ny
        sensors[2] = bump
        sensors[3] = float(wsteps[0])
        sensors[4] = reward
        for r in range(num_regions):
            sensors[5 + r] = 1.0 if inside[r] else 0.0
        for i in range(num_indicators):
            sensors[5 + num_regions + i] = color_values[i, colors[i]] if inside[ind_region[i]] else 0.0
        sensors[5 + num_regions + num_indicators] = 1.0 if terminated else 0.0
        _learn(
            gi, thresholds, si, sf, fixed, wp, stage_lo, stage_hi, node_kind, node_arg, node_start, node_children,
            out_r, out_z, out_g, action, b[action], nx, ny, sensors, terminated, learning, with_metrics,
            theta, w, e, h, de, tau, dstats, feat, pi, q, pred, gamma, delta_out, cumulant, diverged,
            node_values, idx_tp1, q_old, pi_tp1, saved,
        )  # fmt: skip
        steps += 1
        returns[0] += reward
        result[R_ACTION] = action
        result[R_REWARD] = reward
        result[R_TERMINATED] = 1.0 if terminated else 0.0
        result[R_TRUNCATED] = 1.0 if truncated else 0.0
        sign = 0.0
        if terminated:
            tr = _terminal_reward(is_terminal, inside, term_reward, term_ind, term_table, colors)
            sign = 1.0 if tr > 0 else (-1.0 if tr < 0 else 0.0)
        result[R_SIGN] = sign
        if terminated or truncated:
            episodes += 1
            returns[1] = returns[0]
            returns[0] = 0.0
            _world_reset(rng, wp, rects, is_obstacle, is_terminal, color_cdf, color_count, pos, wsteps, colors)
            _start_episode(gi, thresholds, si, sf, fixed, wp, pos[0], pos[1], theta, w, e, feat, pi, q, pred,
                           gamma, q_old, pi_tp1)  # fmt: skip
    result[R_STEPS] = steps
    result[R_EPISODES] = episodes


DIRECTIONS_ = DIRECTIONS.copy()
PERPENDICULAR_ = PERPENDICULAR.astype(np.int64)


# ----------------------------------------------------------------------------------------------
# The Python side: packing, state in and out


class FastLoop:
    """The compiled loop for one agent, packed from a compiled `Horde` and its `World`.

    It owns mutable flat buffers; `horde_state()` and `world_state()` export the numpy engine's
    immutable states (weights as views), `load()` imports them.
    """

    def __init__(self, horde: Horde, world: World) -> None:
        self.horde = horde
        self.world = world
        spec = world.spec
        start = np.asarray(spec.start, dtype=float)
        rect = len(start) == 4
        self.wp = np.array(
            [spec.width, spec.height, spec.step, spec.slip, spec.noise, spec.transient_reward, spec.max_steps,
             1.0 if rect else 0.0, start[0], start[1], start[2] if rect else 0.0, start[3] if rect else 0.0]
        )  # fmt: skip
        self.rects = world.rects.copy()
        self.is_obstacle = world.is_obstacle.astype(np.bool_)
        self.is_terminal = world.is_terminal.astype(np.bool_)
        self.term_reward = world.terminal_reward.copy()
        self.term_ind = world.terminal_indicator.astype(np.int64)
        self.term_table = world.terminal_table.copy()
        self.ind_region = np.array(world.indicator_regions, dtype=np.int64)
        max_colors = max((len(v) for v in world.color_values), default=1)
        self.color_values = np.zeros((world.num_indicators, max_colors))
        self.color_cdf = np.ones((world.num_indicators, max_colors))
        self.color_count = np.zeros(world.num_indicators, dtype=np.int64)
        for i, (values, probs) in enumerate(zip(world.color_values, world.color_probs, strict=True)):
            cdf = np.cumsum(probs)
            self.color_values[i, : len(values)] = values
            self.color_cdf[i, : len(values)] = cdf / cdf[-1]
            self.color_count[i] = len(values)
        self._pack_groups()
        self._pack_programs()
        d = horde.num_demons
        kmax = max((g.coder.k for g in horde.groups), default=1)
        sizes = [len(g.demons) * g.num_features for g in horde.groups]
        total = int(sum(sizes))
        self.theta = np.zeros(total)
        self.w = np.zeros(total)
        self.e = np.zeros(total)
        self.h = np.zeros(total)
        self.de = np.zeros(total)
        self.tau = np.zeros((len(horde.groups), 2))
        self.dstats = np.zeros((d, 3))
        self.feat = np.zeros((len(horde.groups), kmax), dtype=np.int64)
        self.pi = np.full((d, A), 1.0 / A)
        self.q = np.full((d, A), np.nan)
        self.pred = np.zeros(d)
        self.gamma = np.zeros(d)
        self.delta = np.zeros(d)
        self.cumulant = np.zeros(d)
        self.diverged = np.zeros(d, dtype=np.bool_)
        self.pos = np.zeros(2)
        self.wsteps = np.zeros(1, dtype=np.int64)
        self.colors = np.zeros(world.num_indicators, dtype=np.int64)
        self.result = np.zeros(7)
        self.returns = np.zeros(2)  # [this episode's return so far, the last episode's return]
        self.all_learning = np.ones(d, dtype=np.bool_)

    def _pack_groups(self) -> None:
        horde = self.horde
        rows: list[list[int]] = []
        thresholds: list[float] = []
        slots_i: list[list[int]] = []
        slots_f: list[list[float]] = []
        fixed: list[np.ndarray] = []
        offset = 0
        slot = 0
        for g, group in enumerate(horde.groups):
            spec = group.coder.spec
            lo = len(thresholds)
            thresholds.extend(group.coder.thresholds.tolist())
            count = len(group.demons)
            rows.append([
                group.stage, int(group.action_values), group.coder.n, group.num_features, group.coder.k,
                FEATURE_KINDS[spec.kind], spec.parts, spec.tilings, spec.tiles, group.coder.base_n,
                group.condition, lo, len(thresholds), slot, slot + count, offset,
            ])  # fmt: skip
            for row, demon in enumerate(group.demons):
                slots_i.append([int(demon), g, int(group.policy_kind[row]), int(group.of_index[row]),
                                int(group.reset[row])])  # fmt: skip
                p = group.params
                discount = horde.demon_specs[demon].discount
                slots_f.append([p.lam[row], p.alpha[row], p.alpha_w[row], p.rho_in_trace[row], p.correct[row],
                                group.temperature[row], group.epsilon[row], discount])  # fmt: skip
                fixed.append(group.fixed[row])
            slot += count
            offset += count * group.num_features
        self.gi = np.array(rows, dtype=np.int64).reshape(-1, 16)
        self.thresholds = np.array(thresholds, dtype=float)
        self.si = np.array(slots_i, dtype=np.int64).reshape(-1, 5)
        self.sf = np.array(slots_f, dtype=float).reshape(-1, 8)
        self.fixed = np.array(fixed, dtype=float).reshape(-1, A)

    def _pack_programs(self) -> None:
        kinds: list[int] = []
        args: list[float] = []
        starts: list[int] = [0]
        children: list[int] = []
        stage_lo, stage_hi = [], []
        d = self.horde.num_demons
        out_r, out_z, out_g = np.zeros(d, np.int64), np.zeros(d, np.int64), np.zeros(d, np.int64)
        base = 0
        for stage in self.horde.stages:
            k, a, st, ch = stage.program.table()
            kinds.extend(k.tolist())
            args.extend(a.tolist())
            starts.extend((st[1:] + len(children)).tolist())
            children.extend((ch + base).tolist())
            stage_lo.append(base)
            stage_hi.append(base + len(k))
            ds = len(stage.demons)
            outputs = stage.program.outputs + base
            out_r[stage.demons] = outputs[:ds]
            out_z[stage.demons] = outputs[ds : 2 * ds]
            out_g[stage.demons] = outputs[2 * ds :]
            base += len(k)
        self.node_kind = np.array(kinds, dtype=np.int64)
        self.node_arg = np.array(args, dtype=float)
        self.node_start = np.array(starts, dtype=np.int64)
        self.node_children = np.array(children, dtype=np.int64)
        self.stage_lo = np.array(stage_lo, dtype=np.int64)
        self.stage_hi = np.array(stage_hi, dtype=np.int64)
        self.out_r, self.out_z, self.out_g = out_r, out_z, out_g

    def _behaviour(self, behaviour: BehaviourSpec) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        demon = self.horde.index[behaviour.demon] if behaviour.demon else -1
        probs = np.asarray(behaviour.probabilities if behaviour.probabilities else [0.25] * A, dtype=float)
        return (
            np.array([KIND_CODES[behaviour.kind], demon], dtype=np.int64),
            np.array([behaviour.temperature, behaviour.epsilon]),
            probs,
        )

    # ------------------------------------------------------------------------------------------

    def reset_world(self, rng: np.random.Generator) -> None:
        """A new episode: the world draws its start and colours, the Horde observes the first state."""
        _world_reset(rng, self.wp, self.rects, self.is_obstacle, self.is_terminal, self.color_cdf, self.color_count,
                     self.pos, self.wsteps, self.colors)  # fmt: skip
        self.start_episode()

    def start_episode(self) -> None:
        _start_episode(self.gi, self.thresholds, self.si, self.sf, self.fixed, self.wp, self.pos[0], self.pos[1],
                       self.theta, self.w, self.e, self.feat, self.pi, self.q, self.pred, self.gamma,
                       np.zeros(A), np.zeros(A))  # fmt: skip

    def run(
        self,
        rng: np.random.Generator,
        max_steps: int,
        max_episodes: int = 2**62,
        behaviour: BehaviourSpec | None = None,
        learning: np.ndarray | None = None,
        with_metrics: bool = True,
    ) -> np.ndarray:
        """Step until `max_steps` steps or `max_episodes` ended episodes; returns the result fields (R_*)."""
        beh_i, beh_f, beh_probs = self._behaviour(behaviour or self.horde.behaviour)
        self.result[:] = 0.0
        _run(
            max_steps, max_episodes, rng, self.result, self.returns,
            self.wp, self.rects, self.is_obstacle, self.is_terminal, self.term_reward, self.term_ind,
            self.term_table, self.ind_region, self.color_values, self.color_cdf, self.color_count,
            self.pos, self.wsteps, self.colors,
            beh_i, beh_f, beh_probs,
            self.gi, self.thresholds, self.si, self.sf, self.fixed, self.stage_lo, self.stage_hi,
            self.node_kind, self.node_arg, self.node_start, self.node_children,
            self.out_r, self.out_z, self.out_g,
            self.all_learning if learning is None else learning.astype(np.bool_), with_metrics,
            self.theta, self.w, self.e, self.h, self.de, self.tau, self.dstats, self.feat, self.pi, self.q,
            self.pred, self.gamma, self.delta, self.cumulant, self.diverged,
        )  # fmt: skip
        return self.result

    # ------------------------------------------------------------------------------------------

    def _rows(self, g: int, flat: np.ndarray) -> np.ndarray:
        """The [Dg, n] view of group g in a flat buffer."""
        lo, hi, n, off = (int(self.gi[g, c]) for c in (G_SLOT_LO, G_SLOT_HI, G_N, G_OFFSET))
        return flat[off : off + (hi - lo) * n].reshape(hi - lo, n)

    def horde_state(self) -> HordeState:
        """A copy of the state in the numpy engine's form."""
        groups = self.horde.groups

        def rows(g: int, flat: np.ndarray) -> np.ndarray:
            return self._rows(g, flat).copy()

        learner_states = tuple(
            learners.LearnerState(rows(g, self.theta), rows(g, self.w), rows(g, self.e)) for g in range(len(groups))
        )
        metric_states = tuple(
            metrics.MetricsState(
                rows(g, self.h),
                rows(g, self.de),
                float(self.tau[g, 0]),
                self.dstats[group.demons, 0].copy(),
                self.dstats[group.demons, 1].copy(),
                self.dstats[group.demons, 2].copy(),
                float(self.tau[g, 1]),
            )
            for g, group in enumerate(groups)
        )
        return HordeState(
            learners=learner_states,
            metrics=metric_states,
            features=tuple(self.feat[g, : group.coder.k].copy() for g, group in enumerate(groups)),
            pi=self.pi.copy(),
            q=self.q.copy(),
            prediction=self.pred.copy(),
            gamma=self.gamma.copy(),
            delta=self.delta.copy(),
            cumulant=self.cumulant.copy(),
            diverged=self.diverged.copy(),
        )

    def world_state(self) -> WorldState:
        return WorldState(
            x=self.pos[:1].copy(), y=self.pos[1:].copy(), steps=self.wsteps.copy(), colors=self.colors[None, :].copy()
        )

    def load(self, state: HordeState, world_state: WorldState) -> None:
        """Copy a numpy-engine state (and the first agent of a world state) into the buffers."""
        for g, group in enumerate(self.horde.groups):
            learner, metric = state.learners[g], state.metrics[g]
            self._rows(g, self.theta)[:] = learner.theta
            self._rows(g, self.w)[:] = learner.w
            self._rows(g, self.e)[:] = learner.e
            self._rows(g, self.h)[:] = metric.h
            self._rows(g, self.de)[:] = metric.delta_e
            self.tau[g] = (metric.tau_rupee, metric.tau_ude)
            self.dstats[group.demons] = np.stack([metric.delta_mean, metric.delta_square, metric.abs_delta], axis=1)
            self.feat[g, : group.coder.k] = state.features[g]
        self.pi[:] = state.pi
        self.q[:] = state.q
        self.pred[:] = state.prediction
        self.gamma[:] = state.gamma
        self.delta[:] = state.delta
        self.cumulant[:] = state.cumulant
        self.diverged[:] = state.diverged
        self.pos[:] = (world_state.x[0], world_state.y[0])
        self.wsteps[0] = world_state.steps[0]
        self.colors[:] = world_state.colors[0]
