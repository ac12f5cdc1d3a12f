"""The one engine's compiled loop (numba): world, features, questions, policies and block learning.

One call runs many steps of one agent: the world moves, every group's active features are coded, each
stage's question program is evaluated, and every block of demons learns with the kernels of
`scale_fast.py` (feature-major weights, one shared sparse trace per trace class, DESIGN section 6).
`horde.py` compiles the spec into stages, groups, blocks and classes; this module packs them into flat
arrays (`Net`, constant) and buffers (`Buffers`, changed in place) and exports / imports the
`HordeState` of `horde.py`.

Slots number the demons block by block (`Horde.slot_demon`); everything per demon inside the loop is
per slot, and prediction nodes of the question programs read slots.

Divergence: a demon whose TD error, prediction or action values go non-finite or beyond MAX_MAGNITUDE
(`horde.py`) is marked diverged and frozen (its step sizes become 0) and its weights are set to 0
(whatever weights it had left would sum to nonsense elsewhere), so that demons reading its prediction go on.

RUPEE's average of delta e decays by one number per group (`mscale`), so that its decay does not touch
every row at every step; `horde_state()` hands out the product.

The kernels here compile without reference counting (`_nrt=False`, as in `scale_fast.py`): only `_run`
(which allocates its scratch) and the world's reset (the generator) count references.

Why one long module: the learning step lives once, inside `_run`'s loop (see its docstring for why it is
not a function of its own), and the kernels it calls sit beside it; the Python half (`FastLoop`: packing,
state in and out) could move to a module of its own, which is left for a change that can re-measure.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit, prange

from horde.core import metrics
from horde.core.adaptive_kernels import OnlineArrays, online_reset, online_step
from horde.core.features import hashed_tiles
from horde.core.horde import MAX_MAGNITUDE, Horde, HordeState
from horde.core.metrics import RUPEE_ALPHA_H, RUPEE_BETA, UDE_BETA
from horde.core.policies import FIXED, KIND_CODES, OF, UNIFORM
from horde.core.scale import POLICY_CODES
from horde.core.scale_fast import (
    ALIGN,
    B_COFF,
    B_HI,
    B_LEARNER,
    B_LO,
    B_NCLS,
    B_POLICY,
    B_ROWS,
    B_TOFF,
    B_VOFF,
    B_WOFF,
    GQ,
    NO_NRT,
    ONLINE,
    PARALLEL_MIN,
    WITH_NRT,
    _at,
    _observe_block,
    _read_values,
    _step,
    _value_policy,
    settle_owed,
)
from horde.core.world import (
    DIRECTIONS,
    NUM_ACTIONS,
    PERPENDICULAR,
    START_DRAWS,
    ImpossibleStartError,
    World,
    WorldState,
)
from horde.spec import IMPOSSIBLE_START, BehaviourSpec

A = NUM_ACTIONS
FEATURE_KINDS = {"stripes": 0, "tiles": 1, "grid": 2, "constant": 3, "sensors": 4, "table": 5}
FOREVER = 2**62  # "no limit" for step and episode counts

# Per-weight vectors of the adaptive learners beside theta, for `FastLoop.unique_bytes`: true online GTD's w,
# Autostep's step sizes, normaliser and h, TIDBD's step sizes and h.
VECTORS = {"true_online_gtd": 2, "autostep": 3, "tidbd": 2}

# Columns of the per-group integer table.
G_STAGE, G_ACTION_VALUES, G_NS, G_K, G_KIND, G_PARTS, G_TILINGS, G_TILES, G_BASE_N, G_COND = range(10)
G_THR_LO, G_THR_HI, G_BLO, G_BHI, G_CLO, G_CHI, G_SLO, G_SHI, G_SEN_LO, G_SEN_HI = range(10, 20)
G_TABLE, G_TABLE_ROWS, G_TABLE_COL = range(20, 23)  # kind "table": its rows' offset in Net.table, count, sensor
GI_COLUMNS = 23
# World parameters.
W_WIDTH, W_HEIGHT, W_STEP, W_SLIP, W_NOISE, W_TRANSIENT, W_MAX_STEPS, W_START_RECT = range(8)
W_SX0, W_SY0, W_SX1, W_SY1 = range(8, 12)
# Node kinds (questions.NODE_KINDS).
N_CONST, N_SENSOR, N_PREDICTION, N_ADD, N_MUL, N_MIN, N_MAX, N_IF = range(8)
# Result fields of `_run`.
R_STEPS, R_EPISODES, R_ACTION, R_REWARD, R_TERMINATED, R_TRUNCATED, R_SIGN, R_BPROB = range(8)
MSCALE_FLOOR = 1e-200  # RUPEE's lazily decayed average is folded back in below this scale


class Net(NamedTuple):
    """What the loop reads and never changes: the world, the groups, blocks, classes and programs."""

    wp: np.ndarray  # [12] world parameters (W_*)
    rects: np.ndarray  # [R, 4]
    is_obstacle: np.ndarray  # [R] bool
    is_terminal: np.ndarray  # [R] bool
    term_reward: np.ndarray  # [R]
    term_ind: np.ndarray  # [R] indicator slot of a colour-dependent terminal reward, or -1
    term_table: np.ndarray  # [R, colours]
    ind_region: np.ndarray  # [I] region of each indicator
    color_values: np.ndarray  # [I, colours]
    color_cdf: np.ndarray  # [I, colours]
    color_count: np.ndarray  # [I]
    gi: np.ndarray  # [G, 20] the G_* columns
    thresholds: np.ndarray  # conditioned features' thresholds, group g's at G_THR_LO..G_THR_HI
    tiled_col: np.ndarray  # tiled sensors (kind "sensors"), group g's at G_SEN_LO..G_SEN_HI: sensor column
    tiled_low: np.ndarray  # and range
    tiled_high: np.ndarray
    table: np.ndarray  # kind "table": every table's rows of k indices, flat, group g's from G_TABLE
    bi: np.ndarray  # [B, 10] the scale_fast B_* columns (slots and classes global)
    lam: np.ndarray  # [B]
    cut: float
    alpha: np.ndarray  # [D] per slot, divided by the active features
    alpha_w: np.ndarray  # [D]
    temperature: np.ndarray  # [D]
    epsilon: np.ndarray  # [D]
    reset: np.ndarray  # [D] bool: forget the weights at every episode start
    dcls: np.ndarray  # [D] global trace class of each slot
    cls_lo: np.ndarray  # [C] first slot of each class, within its block
    cls_hi: np.ndarray  # [C] one past its last
    class_kind: np.ndarray  # [C] UNIFORM / FIXED / OF, or the kind of an own-value demon
    class_fixed: np.ndarray  # [C, A]
    class_of: np.ndarray  # [C] slot followed, or -1
    class_gnode: np.ndarray  # [C] program node of the class's continuation
    class_discount: np.ndarray  # [C]
    stage_lo: np.ndarray  # [S] first node of each stage's program
    stage_hi: np.ndarray
    node_kind: np.ndarray
    node_arg: np.ndarray  # sensor column, prediction slot or constant
    node_start: np.ndarray
    node_children: np.ndarray
    out_r: np.ndarray  # [D] node of each slot's cumulant
    out_z: np.ndarray  # [D] node of each slot's outcome


class Buffers(NamedTuple):
    """Everything the loop changes, in place."""

    pos: np.ndarray  # [2]
    wsteps: np.ndarray  # [1]
    colors: np.ndarray  # [I]
    sensors: np.ndarray  # [S] at the last s_{t+1}
    start_sensors: np.ndarray  # [S] at the state the Horde last observed afresh (an episode's first state)
    theta: np.ndarray  # blocks' [n_b, Db] at B_WOFF
    w: np.ndarray
    trace: np.ndarray  # blocks' [n_b, C_b] at B_VOFF
    support: np.ndarray  # blocks' sorted support rows at B_TOFF
    nnz: np.ndarray  # [B]
    touched: np.ndarray  # [B] support rows of the last step
    h: np.ndarray  # RUPEE's h, as theta
    u: np.ndarray  # RUPEE's average of delta e, divided by mscale of its group
    hu: np.ndarray  # [D] sum over rows of h * u, kept up to date (RUPEE = sqrt(|mscale hu|))
    mscale: np.ndarray  # [G]
    tau: np.ndarray  # [G, 2]
    dstats: np.ndarray  # [D, 3]
    feat: np.ndarray  # [G, kmax] active features at s_t
    idx: np.ndarray  # [kmax] at s_{t+1}
    tiled_values: np.ndarray  # [most tiled sensors of a group] scratch
    class_gamma: np.ndarray  # [C] at s_t
    class_pi: np.ndarray  # [C, A] at s_t
    pi_given: np.ndarray  # [C, A] at s_{t+1}
    gamma_tp1: np.ndarray  # [C]
    rho: np.ndarray  # [C]
    alpha_now: np.ndarray  # [D] alpha, 0 where frozen
    alpha_w_now: np.ndarray  # [D]
    r: np.ndarray  # [D]
    z: np.ndarray  # [D]
    pi: np.ndarray  # [D, A]
    q: np.ndarray  # [D, A]
    pred: np.ndarray  # [D]
    gamma: np.ndarray  # [D]
    delta: np.ndarray  # [D]
    cumulant: np.ndarray  # [D]
    diverged: np.ndarray  # [D] bool
    node_values: np.ndarray
    rows: np.ndarray  # scratch of the block kernel
    rows_e: np.ndarray
    rows_f: np.ndarray
    values: np.ndarray  # [A, dmax]
    pi_next: np.ndarray  # [A, dmax]
    work: np.ndarray  # [6, dmax]
    owed: np.ndarray  # [A, D] the gradient correction at the last x_{t+1}, owed by theta (`scale_fast._columns`)
    mark: np.ndarray  # [most rows of a block] how often a row is listed at s_{t+1} (GQ's support pass; else 0)
    ex: np.ndarray  # [A, dmax] e . x_bar(s_{t+1}, a) per demon
    ev: np.ndarray  # [2, dmax]
    scratch: np.ndarray  # [2, A]
    returns: np.ndarray  # [2] this episode's return so far, the last episode's
    result: np.ndarray  # [8] the R_* fields


class Given(NamedTuple):
    """Transitions observed outside the grid world (`external.py`), which `_run` learns from in order in
    place of the world's moves: row t is s_t, a_t -> s_{t+1} with s_{t+1}'s sensors. `NO_GIVEN`: the world."""

    sensors: np.ndarray  # [T, S] the sensors of s_{t+1}
    actions: np.ndarray  # [T] a_t
    b_probs: np.ndarray  # [T] b(a_t | s_t)
    terminated: np.ndarray  # [T] bool: s_{t+1} is terminal (only the last row may be)
    rules: np.ndarray  # [R, 5] the target policies of "sign" classes (`_apply_rules`)
    pred_out: np.ndarray  # [T, D] the predictions (slot order) after each row, or [0, D] to keep none


NO_GIVEN = Given(np.zeros((0, 1)), np.zeros(0, np.int64), np.zeros(0), np.zeros(0, np.bool_), np.zeros((0, 5)),
                 np.zeros((0, 1)))  # fmt: skip


# ----------------------------------------------------------------------------------------------
# World


@njit(**NO_NRT)
def _holds(rects, r, x, y):
    """Region r's rectangle holds (x, y): x0 <= x < x1 and y0 <= y < y1."""
    return rects[r, 0] <= x and x < rects[r, 2] and rects[r, 1] <= y and y < rects[r, 3]


@njit(**NO_NRT)
def _inside(wp, rects, x, y, out):
    for r in range(rects.shape[0]):
        out[r] = _holds(rects, r, x, y)


@njit(**NO_NRT)
def _blocked(wp, rects, is_obstacle, x, y):
    if x < 0.0 or x >= wp[W_WIDTH] or y < 0.0 or y >= wp[W_HEIGHT]:
        return True
    for r in range(rects.shape[0]):  # noqa: SIM110 (numba compiles loops, not any() over generators)
        if is_obstacle[r] and _holds(rects, r, x, y):
            return True
    return False


@njit(**NO_NRT)
def _draw(rng, cdf, n):
    """An index drawn from the cumulative weights cdf[:n] with one uniform (the last index if rounding leaves the
    draw past every bound): how the behaviour and the Monte-Carlo rollouts pick an action."""
    draw = rng.random() * cdf[n - 1]
    index = 0
    for a in range(n):
        if draw >= cdf[a]:
            index += 1
    return min(index, n - 1)


@njit(**NO_NRT)
def _displacement(rng, wp, action):
    """The (dx, dy) an action moves the agent: to a perpendicular with probability slip (half each way), one
    step long, plus Gaussian noise on each axis (random draws in this order, as `World.step` makes them)."""
    moved = action
    if wp[W_SLIP] > 0.0:
        u = rng.random()
        if u < wp[W_SLIP]:
            moved = PERPENDICULAR_[action, 1 if u < wp[W_SLIP] / 2 else 0]
    dx = DIRECTIONS_[moved, 0] * wp[W_STEP]
    dy = DIRECTIONS_[moved, 1] * wp[W_STEP]
    if wp[W_NOISE] > 0.0:
        dx = dx + rng.normal(0.0, wp[W_NOISE])
        dy = dy + rng.normal(0.0, wp[W_NOISE])
    return dx, dy


@njit(**NO_NRT)
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
        for draw in range(START_DRAWS + 1):
            if draw == START_DRAWS:
                raise ImpossibleStartError(IMPOSSIBLE_START)
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


@njit(**NO_NRT)
def _terminal_reward(is_terminal, inside, term_reward, term_ind, term_table, colors):
    for r in range(inside.shape[0]):
        if inside[r] and is_terminal[r]:
            if term_ind[r] >= 0:
                return term_table[r, colors[term_ind[r]]]
            return term_reward[r]
    return 0.0


# ----------------------------------------------------------------------------------------------
# Features


@njit(**NO_NRT)
def _cell(u, parts):
    return min(max(math.floor(u * parts), 0), parts - 1)


@njit(**NO_NRT)
def _features(gi, thresholds, tiled_col, tiled_low, tiled_high, tiled_values, table, g, x, y, sensors, condition, wp,
              out):  # fmt: skip
    """Active state features of group g at (x, y) (and its sensors, for kinds "sensors" and "table") into out[:k]."""
    kind = gi[g, G_KIND]
    u = x / wp[W_WIDTH]
    v = y / wp[W_HEIGHT]
    base_n = gi[g, G_BASE_N]
    if kind == 5:  # the row of the sensor's reading (rounded, clipped), as StateCoder.table_row
        k = gi[g, G_K]
        row = min(max(int(np.rint(sensors[gi[g, G_TABLE_COL]])), 0), gi[g, G_TABLE_ROWS] - 1)
        start = gi[g, G_TABLE] + row * k
        for j in range(k):
            out[j] = table[start + j]
    elif kind == 4:
        lo, hi = gi[g, G_SEN_LO], gi[g, G_SEN_HI]
        for j in range(lo, hi):
            tiled_values[j - lo] = sensors[tiled_col[j]]
        hashed_tiles(tiled_values[: hi - lo], tiled_low[lo:hi], tiled_high[lo:hi], gi[g, G_TILINGS], gi[g, G_TILES],
                     base_n - 1, out)  # fmt: skip
        out[gi[g, G_K] - 1] = base_n - 1
    elif kind == 3:
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


@njit(**NO_NRT)
def _behaviour(beh_i, beh_f, beh_probs, q, out):
    A = out.shape[0]  # the world's number of actions
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


@njit(**NO_NRT)
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


@njit(**NO_NRT)
def _sort(a, k):
    """Insertion sort of a[:k] in place (coded features are sorted already: this costs one pass)."""
    for i in range(1, k):
        v = a[i]
        j = i - 1
        while j >= 0 and a[j] > v:
            a[j + 1] = a[j]
            j -= 1
        a[j + 1] = v


@njit(**NO_NRT)
def _given_policies(gi, class_kind, class_of, class_fixed, pi, pi_given, g):
    """pi_given of group g's classes at the state just observed: fixed, uniform, or the followed slot's."""
    A = pi_given.shape[1]
    for c in range(gi[g, G_CLO], gi[g, G_CHI]):
        for a in range(A):
            pi_given[c, a] = pi[class_of[c], a] if class_kind[c] == OF else class_fixed[c, a]


@njit(**NO_NRT)
def _apply_rules(rules, sensors, class_fixed):
    """Target policies of "sign" classes at a state: rules [R, 5] = (class, sensor column, action where
    negative, action where >= 0, epsilon) write (1 - epsilon) on the chosen action plus epsilon / A."""
    A = class_fixed.shape[1]
    for j in range(rules.shape[0]):
        c = int(rules[j, 0])
        epsilon = rules[j, 4]
        for a in range(A):
            class_fixed[c, a] = epsilon / A
        chosen = int(rules[j, 3]) if sensors[int(rules[j, 1])] >= 0.0 else int(rules[j, 2])
        class_fixed[c, chosen] += 1.0 - epsilon


@njit(**NO_NRT)
def _given_to_slots(gi, bi, dcls, pi, pi_given, g):
    """Slots of given-policy blocks take their class's policy (the block kernel sets GQ ones itself)."""
    A = pi.shape[1]
    for b in range(gi[g, G_BLO], gi[g, G_BHI]):
        if bi[b, B_POLICY] != FIXED:
            continue
        for s in range(bi[b, B_LO], bi[b, B_HI]):
            for a in range(A):
                pi[s, a] = pi_given[dcls[s], a]


@njit(**NO_NRT)
def _start_sensors(net, buf):
    """The sensors at an episode's first state: no move yet, so bump, steps, reward and terminal are 0."""
    num_regions = net.rects.shape[0]
    sensors = buf.start_sensors
    sensors[:5] = 0.0
    sensors[0] = buf.pos[0]
    sensors[1] = buf.pos[1]
    for r in range(num_regions):
        sensors[5 + r] = 1.0 if _holds(net.rects, r, buf.pos[0], buf.pos[1]) else 0.0
    for i in range(net.ind_region.shape[0]):
        inside = _holds(net.rects, net.ind_region[i], buf.pos[0], buf.pos[1])
        sensors[5 + num_regions + i] = net.color_values[i, buf.colors[i]] if inside else 0.0
    sensors[sensors.shape[0] - 1] = 0.0


@njit(**NO_NRT)
def _observe(net, buf):
    """An episode starts: reset demons forget, traces to zero, every group observes the first state."""
    bi = net.bi
    for b in range(bi.shape[0]):
        lo, hi, rows, woff = bi[b, B_LO], bi[b, B_HI], bi[b, B_ROWS], bi[b, B_WOFF]
        toff, voff, ncls = bi[b, B_TOFF], bi[b, B_VOFF], bi[b, B_NCLS]
        db = hi - lo
        for i in range(db):
            if net.reset[lo + i]:
                for row in range(rows):
                    buf.theta[woff + row * db + i] = 0.0
                    buf.w[woff + row * db + i] = 0.0
        for s in range(buf.nnz[b]):
            row = buf.support[toff + s]
            buf.trace[voff + row * ncls : voff + (row + 1) * ncls] = 0.0
        buf.nnz[b] = 0
    buf.class_gamma[:] = 0.0
    buf.gamma[:] = 0.0
    for g in range(net.gi.shape[0]):
        k = net.gi[g, G_K]
        cond = buf.pred[net.gi[g, G_COND]] if net.gi[g, G_COND] >= 0 else 0.0
        _features(net.gi, net.thresholds, net.tiled_col, net.tiled_low, net.tiled_high, buf.tiled_values, net.table,
                  g, buf.pos[0], buf.pos[1], buf.start_sensors, cond, net.wp, buf.feat[g])  # fmt: skip
        _sort(buf.feat[g], k)
        _given_policies(net.gi, net.class_kind, net.class_of, net.class_fixed, buf.pi, buf.pi_given, g)
        blo, bhi = net.gi[g, G_BLO], net.gi[g, G_BHI]
        bi_g = bi[blo:bhi]
        for b in range(bhi - blo):
            _read_values(bi_g, b, net.gi[g, G_NS], buf.theta, buf.feat[g, :k], buf.values)
            _observe_block(bi_g, b, net.dcls, net.temperature, net.epsilon, buf.pi_given, buf.values, buf.q,
                           buf.pi, buf.pred, buf.scratch[0], buf.scratch[1])  # fmt: skip
        _given_to_slots(net.gi, bi, net.dcls, buf.pi, buf.pi_given, g)
        for c in range(net.gi[g, G_CLO], net.gi[g, G_CHI]):
            for a in range(buf.class_pi.shape[1]):  # element by element: a slice copy may allocate
                buf.class_pi[c, a] = buf.pi_given[c, a]


@njit(**NO_NRT)
def _slot_diverged(s, gq, delta, pred, q):
    """Whether slot s's TD error, prediction or (GQ) action values are non-finite or beyond MAX_MAGNITUDE."""
    A = q.shape[1]
    bad = not (abs(delta[s]) <= MAX_MAGNITUDE and abs(pred[s]) <= MAX_MAGNITUDE)  # NaN compares False
    if gq:
        for a in range(A):
            bad = bad or not abs(q[s, a]) <= MAX_MAGNITUDE
    return bad


@njit(**NO_NRT)
def _any_diverged(gi, bi, g, delta, pred, q, diverged):
    """Whether a demon of group g not yet marked has diverged (`_slot_diverged`)."""
    for b in range(gi[g, G_BLO], gi[g, G_BHI]):
        gq = bi[b, B_LEARNER] == GQ
        for s in range(bi[b, B_LO], bi[b, B_HI]):
            if not diverged[s] and _slot_diverged(s, gq, delta, pred, q):
                return True
    return False


@njit(**NO_NRT)
def _freeze_diverged(net, buf, g):
    """Mark demons of group g that have diverged (`_slot_diverged`); freeze them and set their weights to 0."""
    bi = net.bi
    blo, bhi = net.gi[g, G_BLO], net.gi[g, G_BHI]
    k = net.gi[g, G_K]
    for b in range(blo, bhi):
        lo, hi, rows, woff = bi[b, B_LO], bi[b, B_HI], bi[b, B_ROWS], bi[b, B_WOFF]
        db = hi - lo
        found = False
        for i in range(db):
            s = lo + i
            if buf.diverged[s] or not _slot_diverged(s, bi[b, B_LEARNER] == GQ, buf.delta, buf.pred, buf.q):
                continue
            found = True
            buf.owed[:, s] = 0.0  # its weights are all 0: nothing is owed
            buf.diverged[s] = True
            buf.alpha_now[s] = 0.0
            buf.alpha_w_now[s] = 0.0
            for row in range(rows):
                buf.theta[woff + row * db + i] = 0.0
                buf.w[woff + row * db + i] = 0.0
        if found:  # read the block's values again with the cleaned weights (the others' owed paid first)
            settle_owed(bi, b, net.gi[g, G_NS], buf.theta, buf.idx[:k], buf.owed)
            bi_g = bi[blo:bhi]
            _read_values(bi_g, b - blo, net.gi[g, G_NS], buf.theta, buf.idx[:k], buf.values)
            _observe_block(bi_g, b - blo, net.dcls, net.temperature, net.epsilon, buf.pi_given, buf.values, buf.q,
                           buf.pi, buf.pred, buf.scratch[0], buf.scratch[1])  # fmt: skip


@njit(**NO_NRT)
def _metrics(gi, bi, cls_lo, cls_hi, g, action, x_t, delta, h, u, hu, mscale, tau, dstats, trace, support, nnz, hx,
             threads):  # fmt: skip
    """RUPEE and UDE of group g after its step (metrics.update, with the average of delta e scaled lazily).

    hu[s] keeps sum_rows h * u of each slot up to date as rows change, so that RUPEE is read in O(D).
    Each demon's numbers touch only its own column of h and u (`_metrics_columns`), so a block of at
    least PARALLEL_MIN demons splits its demons over `threads` threads (`_metrics_parallel`), the same
    numbers to the last bit whatever the count.
    """
    k = gi[g, G_K]
    n_s = gi[g, G_NS]
    blo, bhi = gi[g, G_BLO], gi[g, G_BHI]
    tau[g, 0] = (1 - RUPEE_BETA) * tau[g, 0] + RUPEE_BETA
    tau[g, 1] = (1 - UDE_BETA) * tau[g, 1] + UDE_BETA
    beta = RUPEE_BETA / tau[g, 0]
    decayed = mscale[g] * (1.0 - beta)
    if decayed < MSCALE_FLOOR:  # fold the scale back in (the first step's beta is 1): one pass over the group
        for b in range(blo, bhi):
            woff, size = bi[b, B_WOFF], bi[b, B_ROWS] * (bi[b, B_HI] - bi[b, B_LO])
            for j in range(woff, woff + size):
                u[j] *= decayed
            for s in range(bi[b, B_LO], bi[b, B_HI]):
                hu[s] *= decayed
        decayed = 1.0
    mscale[g] = decayed
    gain = beta / mscale[g]
    alpha_h = RUPEE_ALPHA_H / k
    b_ude = UDE_BETA / tau[g, 1]
    for b in range(blo, bhi):
        db = bi[b, B_HI] - bi[b, B_LO]
        shift = action * n_s if bi[b, B_LEARNER] == GQ else 0
        if threads > 1 and db >= PARALLEL_MIN:
            _metrics_parallel(threads, bi, b, cls_lo, cls_hi, shift, x_t, delta, h, u, hu, dstats, trace, support, nnz,
                              hx, alpha_h, gain, b_ude)  # fmt: skip
        else:
            _metrics_columns(bi, b, 0, db, cls_lo, cls_hi, shift, x_t, delta, h, u, hu, dstats, trace, support, nnz, hx,
                             alpha_h, gain, b_ude)  # fmt: skip


@njit(cache=True, parallel=True, **WITH_NRT)  # prange allocates: NRT on (a caller without it would pass its flag down)
def _metrics_parallel(threads, bi, b, cls_lo, cls_hi, shift, x_t, delta, h, u, hu, dstats, trace, support, nnz, hx,
                      alpha_h, gain, b_ude):  # fmt: skip
    """`_metrics_columns` of block b on `threads` threads, each over one run of the block's demons (runs
    aligned as `scale_fast._columns_parallel` aligns them)."""
    db = bi[b, B_HI] - bi[b, B_LO]
    runs = min(threads, (db + ALIGN - 1) // ALIGN)
    width = ((db + runs - 1) // runs + ALIGN - 1) // ALIGN * ALIGN
    for t in prange(runs):
        i0 = min(t * width, db)
        i1 = min(i0 + width, db)
        _metrics_columns(bi, b, i0, i1, cls_lo, cls_hi, shift, x_t, delta, h, u, hu, dstats, trace, support, nnz, hx,
                         alpha_h, gain, b_ude)  # fmt: skip


@njit(**NO_NRT)
def _metrics_columns(bi, b, i0, i1, cls_lo, cls_hi, shift, x_t, delta, h, u, hu, dstats, trace, support, nnz, hx,
                     alpha_h, gain, b_ude):  # fmt: skip
    """RUPEE's h, u and h . u and UDE's averages of block b's demons i0 <= i < i1: only their columns of h, u
    and of hx (h . x_t at [i], delta at [db + i]) are touched."""
    lo, hi, woff, toff = bi[b, B_LO], bi[b, B_HI], bi[b, B_WOFF], bi[b, B_TOFF]
    voff, ncls, coff = bi[b, B_VOFF], bi[b, B_NCLS], bi[b, B_COFF]
    db = hi - lo
    for i in range(i0, i1):
        hx[i] = 0.0
    for j in range(x_t.shape[0]):
        start = _at(woff + (shift + x_t[j]) * db)
        for i in range(i0, i1):
            hx[i] += h[start + _at(i)]
    for i in range(i0, i1):
        d = delta[lo + i]
        if not math.isfinite(d):
            d = 0.0
        dstats[lo + i, 0] = (1 - b_ude) * dstats[lo + i, 0] + b_ude * d
        dstats[lo + i, 1] = (1 - b_ude) * dstats[lo + i, 1] + b_ude * d * d
        dstats[lo + i, 2] = (1 - b_ude) * dstats[lo + i, 2] + b_ude * abs(d)
        hx[db + i] = d  # delta, 0 where not finite
    for s in range(nnz[b]):  # the trace's support: a class's demons are a run of columns sharing its entry
        row = support[toff + s]
        start = _at(woff + row * db)
        for c in range(ncls):
            ev = trace[voff + row * ncls + c]
            if ev == 0.0:  # (h and u would not change)
                continue
            for i in range(max(i0, cls_lo[coff + c]), min(i1, cls_hi[coff + c])):
                d = hx[db + i]
                at = start + _at(i)
                h0, u0 = h[at], u[at]
                h1, u1 = h0 + alpha_h * d * ev, u0 + gain * d * ev
                h[at], u[at] = h1, u1
                hu[lo + i] += h1 * u1 - h0 * u0
    for j in range(x_t.shape[0]):
        start = _at(woff + (shift + x_t[j]) * db)
        for i in range(i0, i1):
            h0 = h[start + _at(i)]
            h1 = h0 - alpha_h * hx[i]
            h[start + _at(i)] = h1
            hu[lo + i] += (h1 - h0) * u[start + _at(i)]


@njit(cache=True, nogil=True)  # releases the GIL: the server's other threads go on while a run learns
def _run(net, buf, rng, max_steps, max_episodes, beh_i, beh_f, beh_probs, with_metrics, onl, threads, given):
    """`_loop` with its scratch allocated (here, with reference counting: the loop itself counts none)."""
    hx = np.zeros(2 * max(1, buf.work.shape[1]))  # h . x_t and delta of a block, for the metrics
    inside = np.zeros(net.rects.shape[0], dtype=np.bool_)
    b = np.zeros(A)
    cdf = np.zeros(A)
    _loop(net, buf, rng, max_steps, max_episodes, beh_i, beh_f, beh_probs, with_metrics, onl, threads, given, hx,
          inside, b, cdf)  # fmt: skip


@njit(**NO_NRT, nogil=True)
def _loop(net, buf, rng, max_steps, max_episodes, beh_i, beh_f, beh_probs, with_metrics, onl, threads, given, hx,
          inside, b, cdf):  # fmt: skip
    """The one loop: run steps until `max_steps` steps or `max_episodes` episode ends. Each step takes a
    transition from its source, then every demon learns from it (the one learning step of the engine).

    The source is the grid world (`given` is NO_GIVEN: the behaviour acts, the world moves, and new
    episodes start as they end) or the rows of `given` (`external.py`: row t's sensors, action and
    b(a_t | s_t); the caller starts episodes), learned at position (0, 0).
    Blocks of many demons learn on `threads` threads (`scale_fast._step`; the same numbers whatever it is).

    The learning step is written out here, inside the loop, rather than in a function of `net` and `buf`:
    passing (or inlining) the two named tuples of ~40 arrays costs about a microsecond per step (every
    array's count is taken and given back), which is a third of a thesis-scale step (measured: a
    function inlined by numba made the thesis loop 1.3 times slower).

    Compiled without reference counting (its scratch comes from `_run`): with counting, every array
    read from `net` and `buf` or sliced (a group's blocks, its active features, the work rows: about 15
    a group and step) took and gave back a count; without, the thesis loop takes 1.5 to 1.65 times
    fewer CPU seconds (docs/performance.md). So no slice is copied here (an element loop instead).
    """
    from_world = given.sensors.shape[0] == 0
    wp, rects, is_obstacle, is_terminal = net.wp, net.rects, net.is_obstacle, net.is_terminal
    gi, bi, lam, dcls, cls_lo, cls_hi = net.gi, net.bi, net.lam, net.dcls, net.cls_lo, net.cls_hi
    temperature, epsilon, thresholds = net.temperature, net.epsilon, net.thresholds
    class_kind, class_of, class_fixed, class_gnode, class_discount = (
        net.class_kind, net.class_of, net.class_fixed, net.class_gnode, net.class_discount
    )  # fmt: skip
    stage_lo, stage_hi, node_kind, node_arg, node_start, node_children = (
        net.stage_lo, net.stage_hi, net.node_kind, net.node_arg, net.node_start, net.node_children
    )  # fmt: skip
    out_r, out_z = net.out_r, net.out_z
    tiled_col, tiled_low, tiled_high, tiled_values = net.tiled_col, net.tiled_low, net.tiled_high, buf.tiled_values
    pos, sensors, result, returns, colors = buf.pos, buf.sensors, buf.result, buf.returns, buf.colors
    theta, w, trace, support, nnz, touched = buf.theta, buf.w, buf.trace, buf.support, buf.nnz, buf.touched
    feat, idx, node_values = buf.feat, buf.idx, buf.node_values
    class_gamma, class_pi, pi_given, gamma_tp1, rho = (
        buf.class_gamma, buf.class_pi, buf.pi_given, buf.gamma_tp1, buf.rho
    )  # fmt: skip
    alpha_now, alpha_w_now, r_s, z_s = buf.alpha_now, buf.alpha_w_now, buf.r, buf.z
    pi, q, pred, gamma, delta, cumulant, diverged = (
        buf.pi, buf.q, buf.pred, buf.gamma, buf.delta, buf.cumulant, buf.diverged
    )  # fmt: skip
    h, u, hu, mscale, tau, dstats = buf.h, buf.u, buf.hu, buf.mscale, buf.tau, buf.dstats
    rows_, rows_e, rows_f, values, pi_next, work, ev, scratch = (
        buf.rows, buf.rows_e, buf.rows_f, buf.values, buf.pi_next, buf.work, buf.ev, buf.scratch
    )  # fmt: skip
    num_actions = class_pi.shape[1]
    num_regions = rects.shape[0]
    num_indicators = net.ind_region.shape[0]
    steps = 0
    episodes = 0
    while steps < max_steps and episodes < max_episodes:
        if not from_world:  # the next given transition
            for j in range(sensors.shape[0]):
                sensors[j] = given.sensors[steps, j]
            _apply_rules(given.rules, sensors, class_fixed)
            action, b_prob, terminated = given.actions[steps], given.b_probs[steps], given.terminated[steps]
            nx = ny = reward = terminal = 0.0
            truncated = False
        else:  # the behaviour acts, the world moves
            _behaviour(beh_i, beh_f, beh_probs, q, b)
            total = 0.0
            for a in range(A):
                total += b[a]
                cdf[a] = total
            action = _draw(rng, cdf, A)
            dx, dy = _displacement(rng, wp, action)
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
            terminal = 0.0
            if terminated:
                terminal = _terminal_reward(is_terminal, inside, net.term_reward, net.term_ind, net.term_table, colors)
            reward = wp[W_TRANSIENT] + terminal
            buf.wsteps[0] += 1
            truncated = buf.wsteps[0] >= wp[W_MAX_STEPS] and not terminated
            pos[0] = nx
            pos[1] = ny
            sensors[0] = nx
            sensors[1] = ny
            sensors[2] = bump
            sensors[3] = float(buf.wsteps[0])
            sensors[4] = reward
            for r in range(num_regions):
                sensors[5 + r] = 1.0 if inside[r] else 0.0
            for i in range(num_indicators):
                sensors[5 + num_regions + i] = net.color_values[i, colors[i]] if inside[net.ind_region[i]] else 0.0
            sensors[5 + num_regions + num_indicators] = 1.0 if terminated else 0.0
            b_prob = b[action]

        # Every demon learns, stage by stage, group by group (the equations of scale.step).
        current_stage = -1
        for g in range(gi.shape[0]):
            stage = gi[g, G_STAGE]
            if stage != current_stage:
                current_stage = stage
                _evaluate(stage_lo[stage], stage_hi[stage], node_kind, node_arg, node_start, node_children,
                          sensors, pred, node_values)  # fmt: skip
            k = gi[g, G_K]
            cond = pred[gi[g, G_COND]] if gi[g, G_COND] >= 0 else 0.0
            _features(gi, thresholds, tiled_col, tiled_low, tiled_high, tiled_values, net.table, g, nx, ny, sensors,
                      cond, wp, idx)  # fmt: skip
            _sort(idx, k)
            clo, chi = gi[g, G_CLO], gi[g, G_CHI]
            for c in range(clo, chi):
                g1 = min(max(node_values[class_gnode[c]], 0.0), 1.0) * class_discount[c]
                gamma_tp1[c] = 0.0 if terminated else g1
                rho[c] = class_pi[c, action] / b_prob
            _given_policies(gi, class_kind, class_of, class_fixed, pi, pi_given, g)
            slo, shi = gi[g, G_SLO], gi[g, G_SHI]
            for s in range(slo, shi):
                r_s[s] = node_values[out_r[s]]
                z_s[s] = node_values[out_z[s]]
            blo, bhi = gi[g, G_BLO], gi[g, G_BHI]
            _step(
                bi[blo:bhi], lam[blo:bhi], alpha_now, alpha_w_now, temperature, epsilon, dcls, cls_lo, cls_hi,
                net.cut, gi[g, G_NS], theta, w, trace, support, rows_, rows_e, rows_f, nnz[blo:bhi], feat[g, :k],
                action, b_prob, idx[:k], r_s, z_s, gamma_tp1, rho, pi_given, class_gamma, q, pi, pred, delta,
                touched[blo:bhi], values, pi_next, work[0], work[1], work[2], work[3], buf.owed, buf.mark, buf.ex, ev,
                work[4], work[5], scratch[0], scratch[1], threads,
            )  # fmt: skip
            for ob in range(blo, bhi):  # the learners of adaptive_kernels.py, which _step skips
                if bi[ob, B_LEARNER] >= ONLINE:  # it reads the values at x_{t+1} itself (on the threads)
                    online_step(bi, ob, lam[ob], alpha_now, alpha_w_now, dcls, net.cut, theta, w, trace, support, rows_,
                                nnz, feat[g, :k], idx[:k], r_s, z_s, gamma_tp1, rho, class_gamma, q, pred, delta,
                                touched, values, onl, threads)  # fmt: skip
            _given_to_slots(gi, bi, dcls, pi, pi_given, g)
            for c in range(clo, chi):
                for a in range(num_actions):  # the Horde's actions (a given world may have other than A)
                    class_pi[c, a] = pi_given[c, a]
            for s in range(slo, shi):
                gamma[s] = gamma_tp1[dcls[s]]
                cumulant[s] = r_s[s]
            if _any_diverged(gi, bi, g, delta, pred, q, diverged):
                _freeze_diverged(net, buf, g)
            if with_metrics:
                _metrics(gi, bi, cls_lo, cls_hi, g, action, feat[g, :k], delta, h, u, hu, mscale, tau, dstats, trace,
                         support, nnz, hx, threads)  # fmt: skip
            for j in range(k):
                feat[g, j] = idx[j]

        steps += 1
        if not from_world:
            if given.pred_out.shape[0] > 0:
                for j in range(pred.shape[0]):
                    given.pred_out[steps - 1, j] = pred[j]
            continue
        returns[0] += reward
        result[R_ACTION] = action
        result[R_REWARD] = reward
        result[R_TERMINATED] = 1.0 if terminated else 0.0
        result[R_TRUNCATED] = 1.0 if truncated else 0.0
        result[R_SIGN] = 1.0 if terminal > 0 else (-1.0 if terminal < 0 else 0.0)
        result[R_BPROB] = b_prob
        if terminated or truncated:
            _settle_all(net, buf)
            episodes += 1
            returns[1] = returns[0]
            returns[0] = 0.0
            _world_reset(rng, wp, rects, is_obstacle, is_terminal, net.color_cdf, net.color_count, pos, buf.wsteps,
                         colors)  # fmt: skip
            _start_sensors(net, buf)
            _observe(net, buf)
            online_reset(bi, net.reset, net.alpha, onl)
    _settle_all(net, buf)  # whoever reads theta after the loop sees it whole
    result[R_STEPS] = steps
    result[R_EPISODES] = episodes


@njit(**NO_NRT)
def _settle_all(net, buf):
    """Pay every block's owed gradient correction on its group's x_t (`scale_fast._columns`)."""
    for g in range(net.gi.shape[0]):
        k = net.gi[g, G_K]
        for b in range(net.gi[g, G_BLO], net.gi[g, G_BHI]):
            settle_owed(net.bi, b, net.gi[g, G_NS], buf.theta, buf.feat[g, :k], buf.owed)


@njit(cache=True)
def _reset(net, buf, rng):
    """A new episode: the world draws its start and colours, the Horde observes the first state."""
    _world_reset(rng, net.wp, net.rects, net.is_obstacle, net.is_terminal, net.color_cdf, net.color_count, buf.pos,
                 buf.wsteps, buf.colors)  # fmt: skip
    _start_sensors(net, buf)
    _observe(net, buf)


DIRECTIONS_ = DIRECTIONS.copy()
PERPENDICULAR_ = PERPENDICULAR.astype(np.int64)


# ----------------------------------------------------------------------------------------------
# The Python side: packing, state in and out


def _pack_world(world: World) -> dict[str, np.ndarray]:
    spec = world.spec
    start = np.asarray(spec.start, dtype=float)
    rect = len(start) == 4
    wp = np.array(
        [spec.width, spec.height, spec.step, spec.slip, spec.noise, spec.transient_reward, spec.max_steps,
         1.0 if rect else 0.0, start[0], start[1], start[2] if rect else 0.0, start[3] if rect else 0.0]
    )  # fmt: skip
    max_colors = max((len(v) for v in world.color_values), default=1)
    color_values = np.zeros((world.num_indicators, max_colors))
    color_cdf = np.ones((world.num_indicators, max_colors))
    color_count = np.zeros(world.num_indicators, dtype=np.int64)
    for i, (values, probs) in enumerate(zip(world.color_values, world.color_probs, strict=True)):
        cdf = np.cumsum(probs)
        color_values[i, : len(values)] = values
        color_cdf[i, : len(values)] = cdf / cdf[-1]
        color_count[i] = len(values)
    return {
        "wp": wp,
        "rects": world.rects.copy(),
        "is_obstacle": world.is_obstacle.astype(np.bool_),
        "is_terminal": world.is_terminal.astype(np.bool_),
        "term_reward": world.terminal_reward.copy(),
        "term_ind": world.terminal_indicator.astype(np.int64),
        "term_table": world.terminal_table.copy(),
        "ind_region": np.array(world.indicator_regions, dtype=np.int64).reshape(-1),
        "color_values": color_values,
        "color_cdf": color_cdf,
        "color_count": color_count,
    }


def _pack_programs(horde: Horde) -> dict[str, np.ndarray]:
    """The stages' question programs in one node table; prediction nodes read slots."""
    kinds: list[int] = []
    args: list[float] = []
    starts: list[int] = [0]
    children: list[int] = []
    stage_lo, stage_hi = [], []
    d = horde.num_demons
    out = np.zeros((3, d), np.int64)  # per demon: nodes of cumulant, outcome, continuation
    base = 0
    for stage in horde.stages:
        k, a, st, ch = stage.program.table()
        a = a.copy()
        predictions = k == N_PREDICTION
        a[predictions] = horde.demon_slot[a[predictions].astype(np.int64)]
        kinds.extend(k.tolist())
        args.extend(a.tolist())
        starts.extend((st[1:] + len(children)).tolist())
        children.extend((ch + base).tolist())
        stage_lo.append(base)
        stage_hi.append(base + len(k))
        ds = len(stage.demons)
        outputs = stage.program.outputs + base
        for j in range(3):
            out[j, stage.demons] = outputs[j * ds : (j + 1) * ds]
        base += len(k)
    slot_out = out[:, horde.slot_demon]
    discount = np.array([s.discount for s in horde.demon_specs], dtype=float)
    return {
        "stage_lo": np.array(stage_lo, dtype=np.int64),
        "stage_hi": np.array(stage_hi, dtype=np.int64),
        "node_kind": np.array(kinds, dtype=np.int64),
        "node_arg": np.array(args, dtype=float),
        "node_start": np.array(starts, dtype=np.int64),
        "node_children": np.array(children, dtype=np.int64),
        "out_r": slot_out[0].copy(),
        "out_z": slot_out[1].copy(),
        "class_gnode": out[2, horde.class_demon].copy(),
        "class_discount": discount[horde.class_demon],
    }


def _online_arrays(horde: Horde, net: Net, weights: int, traces: int, dmax: int) -> OnlineArrays:
    """The state of adaptive_kernels.py's learners, fresh: per-weight step sizes at alpha, scales 1."""
    blocks = horde.blocks
    cls_alpha = np.zeros(horde.num_classes)
    cls_beta = np.zeros(horde.num_classes)
    cls_alpha[horde.slot_class] = net.alpha  # the demons of a true online class share alpha (and alpha_w)
    cls_beta[horde.slot_class] = net.alpha_w
    sizes = [b.size for b in blocks]
    step_a = np.concatenate([np.tile(b.alpha, int(r)) for b, r in zip(blocks, horde.block_rows, strict=True)]) if (
        blocks) else np.zeros(0)  # fmt: skip
    assert len(step_a) == weights and sum(sizes) == horde.num_demons
    meta = np.concatenate([np.asarray(b.meta if b.meta is not None else np.zeros(b.size)) for b in blocks]) if (
        blocks) else np.zeros(0)  # fmt: skip
    return OnlineArrays(
        v_old=np.zeros(horde.num_demons),
        cls_alpha=cls_alpha,
        cls_beta=cls_beta,
        cls_f=np.zeros(horde.num_classes),
        cls_rho_prev=np.zeros(horde.num_classes),
        trace2=np.zeros(2 * traces),
        step_a=step_a,
        step_v=np.zeros(weights),
        ascale=np.ones(horde.num_demons),
        meta=meta.astype(float),
        tau=np.array([float(horde.spec.learning.autostep_tau)]),
        scratch=np.zeros((8, dmax)),
        bounds=np.zeros(dmax + 1, np.int64),
    )


class FastLoop:
    """The compiled loop for one agent: a compiled `Horde` and its `World` in flat buffers.

    `horde_state()` and `world_state()` export copies in `horde.py`'s and `world.py`'s forms; `load()`
    imports them.
    """

    def __init__(self, horde: Horde, world: World) -> None:
        """Pack a compiled Horde and its world into the loop's arrays.

        Why about 120 lines: it builds the two named tuples the kernels take, `Net` and `Buffers`, field by
        field (one array per line, its shape read where it is made).
        """
        self.horde = horde
        self.world = world
        groups, blocks = horde.groups, horde.blocks
        rows = horde.block_rows
        sizes = np.array([b.size for b in blocks], dtype=np.int64)
        ncls = np.array([b.num_classes for b in blocks], dtype=np.int64)
        woff = np.cumsum([0, *(rows * sizes)]).astype(np.int64)
        toff = np.cumsum([0, *rows]).astype(np.int64)
        voff = np.cumsum([0, *(rows * ncls)]).astype(np.int64)
        class_lo = np.cumsum([0, *ncls])[:-1]
        codes = ([b.code for b in blocks], [POLICY_CODES[b.policy] for b in blocks])
        columns = (*codes, horde.block_lo, horde.block_lo + sizes, rows, woff[:-1], toff[:-1], voff[:-1], ncls,
                   class_lo)  # fmt: skip
        bi = np.stack([np.asarray(c, dtype=np.int64) for c in columns], axis=1).reshape(-1, 10)
        thresholds: list[float] = []
        tiled: list[tuple[int, float, float]] = []
        tables: list[np.ndarray] = []
        table_at = 0
        gi = []
        for group in groups:
            spec = group.coder.spec
            lo = len(thresholds)
            thresholds.extend(group.coder.thresholds.tolist())
            slo = int(horde.block_lo[group.blocks.start]) if len(group.blocks) else 0
            sen_lo = len(tiled)
            tiled.extend(zip(group.coder.tiled_columns.tolist(), group.coder.tiled_low.tolist(),
                             group.coder.tiled_high.tolist(), strict=True))  # fmt: skip
            gi.append([
                group.stage, int(group.action_values), group.coder.n, group.coder.k, FEATURE_KINDS[spec.kind],
                spec.parts, spec.tilings, spec.tiles, group.coder.base_n,
                int(horde.demon_slot[group.condition]) if group.condition >= 0 else -1, lo, len(thresholds),
                group.blocks.start, group.blocks.stop, group.classes.start, group.classes.stop,
                slo, slo + len(group.demons), sen_lo, len(tiled),
                table_at, len(group.coder.table), group.coder.table_column,
            ])  # fmt: skip
            if spec.kind == "table":
                tables.append(group.coder.table.ravel())
                table_at += group.coder.table.size
        starts = [np.searchsorted(np.asarray(b.classes), np.arange(b.num_classes)) for b in blocks]
        ends = [np.searchsorted(np.asarray(b.classes), np.arange(b.num_classes), side="right") for b in blocks]
        slot = horde.slot_demon
        specs = horde.demon_specs
        self.net = Net(
            **_pack_world(world),
            gi=np.array(gi, dtype=np.int64).reshape(-1, GI_COLUMNS),
            thresholds=np.array(thresholds, dtype=float),
            tiled_col=np.array([t[0] for t in tiled], dtype=np.int64),
            tiled_low=np.array([t[1] for t in tiled], dtype=float),
            tiled_high=np.array([t[2] for t in tiled], dtype=float),
            table=np.concatenate(tables) if tables else np.zeros(1, np.int64),
            bi=bi,
            lam=np.array([b.lam for b in blocks], dtype=float),
            cut=float(horde.cut),
            alpha=np.concatenate([b.alpha for b in blocks]) if blocks else np.zeros(0),
            alpha_w=np.concatenate([b.alpha_w for b in blocks]) if blocks else np.zeros(0),
            temperature=np.concatenate([np.asarray(b.temperature) for b in blocks]) if blocks else np.zeros(0),
            epsilon=np.concatenate([np.asarray(b.epsilon) for b in blocks]) if blocks else np.zeros(0),
            reset=np.array([specs[i].reset == "episode" for i in slot], dtype=np.bool_).reshape(-1),
            dcls=horde.slot_class,
            cls_lo=np.concatenate(starts).astype(np.int64) if blocks else np.zeros(0, np.int64),
            cls_hi=np.concatenate(ends).astype(np.int64) if blocks else np.zeros(0, np.int64),
            class_kind=horde.class_kind,
            class_fixed=horde.class_fixed,
            class_of=np.where(horde.class_of >= 0, horde.demon_slot[np.maximum(horde.class_of, 0)], -1),
            **_pack_programs(horde),
        )
        d, c, ng = horde.num_demons, horde.num_classes, len(groups)
        na = horde.num_actions
        kmax = max((g.coder.k for g in groups), default=1)
        dmax = max([1, *sizes.tolist(), *ncls.tolist()])
        most = int(max([1, *rows.tolist()])) + kmax
        self.buf = Buffers(
            pos=np.zeros(2),
            wsteps=np.zeros(1, dtype=np.int64),
            colors=np.zeros(world.num_indicators, dtype=np.int64),
            sensors=np.zeros(len(world.sensor_names)),
            start_sensors=np.zeros(len(world.sensor_names)),
            theta=np.zeros(int(woff[-1])),
            w=np.zeros(int(woff[-1])),
            trace=np.zeros(int(voff[-1])),
            support=np.zeros(int(toff[-1]), np.int64),
            nnz=np.zeros(len(blocks), np.int64),
            touched=np.zeros(len(blocks), np.int64),
            h=np.zeros(int(woff[-1])),
            u=np.zeros(int(woff[-1])),
            hu=np.zeros(d),
            mscale=np.ones(ng),
            tau=np.zeros((ng, 2)),
            dstats=np.zeros((d, 3)),
            feat=np.zeros((ng, kmax), dtype=np.int64),
            idx=np.zeros(kmax, dtype=np.int64),
            tiled_values=np.zeros(max([1, *(len(g.coder.tiled_columns) for g in groups)])),
            class_gamma=np.zeros(c),
            class_pi=np.full((c, na), 1.0 / na),
            pi_given=np.full((c, na), 1.0 / na),
            gamma_tp1=np.zeros(c),
            rho=np.ones(c),
            alpha_now=self.net.alpha.copy(),
            alpha_w_now=self.net.alpha_w.copy(),
            r=np.zeros(d),
            z=np.zeros(d),
            pi=np.full((d, na), 1.0 / na),
            q=np.zeros((d, na)),
            pred=np.zeros(d),
            gamma=np.zeros(d),
            delta=np.zeros(d),
            cumulant=np.zeros(d),
            diverged=np.zeros(d, dtype=np.bool_),
            node_values=np.zeros(len(self.net.node_kind)),
            rows=np.zeros(most, np.int64),
            rows_e=np.zeros(most),
            rows_f=np.zeros(most),
            values=np.zeros((na, dmax)),
            pi_next=np.zeros((na, dmax)),
            work=np.zeros((6, dmax)),
            owed=np.zeros((na, d)),
            mark=np.zeros(int(max([1, *rows.tolist()])), np.int64),
            ex=np.zeros((na, dmax)),
            ev=np.zeros((2, dmax)),
            scratch=np.zeros((2, na)),
            returns=np.zeros(2),
            result=np.zeros(8),
        )
        self._woff, self._voff, self._toff = woff, voff, toff
        for b, theta in enumerate(horde.initial_theta()):  # demons with initial_weights start from them
            self._weights(self.buf.theta, b)[:] = theta
        self.onl = _online_arrays(horde, self.net, int(woff[-1]), int(voff[-1]), dmax)

    # ------------------------------------------------------------------------------------------
    # Views of the buffers

    @property
    def pos(self) -> np.ndarray:
        return self.buf.pos

    @property
    def returns(self) -> np.ndarray:
        return self.buf.returns

    def prediction(self) -> np.ndarray:
        """[D] predictions in demon order (a copy)."""
        out = np.empty(self.horde.num_demons)
        out[self.horde.slot_demon] = self.buf.pred
        return out

    def _block(self, flat: np.ndarray, b: int, columns: int, offsets: np.ndarray) -> np.ndarray:
        rows = int(self.horde.block_rows[b])
        return flat[offsets[b] : offsets[b] + rows * columns].reshape(rows, columns)

    def _weights(self, flat: np.ndarray, b: int) -> np.ndarray:
        return self._block(flat, b, self.horde.blocks[b].size, self._woff)

    def _traces(self, b: int) -> np.ndarray:
        return self._block(self.buf.trace, b, self.horde.blocks[b].num_classes, self._voff)

    # ------------------------------------------------------------------------------------------

    def _behaviour(self, behaviour: BehaviourSpec) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        demon = int(self.horde.demon_slot[self.horde.index[behaviour.demon]]) if behaviour.demon else -1
        na = self.horde.num_actions
        probs = np.asarray(behaviour.probabilities if behaviour.probabilities else [1.0 / na] * na, dtype=float)
        return (
            np.array([KIND_CODES[behaviour.kind], demon], dtype=np.int64),
            np.array([behaviour.temperature, behaviour.epsilon]),
            probs,
        )

    def reset_world(self, rng: np.random.Generator) -> None:
        """A new episode: the world draws its start and colours, the Horde observes the first state."""
        _reset(self.net, self.buf, rng)
        online_reset(self.net.bi, self.net.reset, self.net.alpha, self.onl)

    def run(
        self,
        rng: np.random.Generator,
        max_steps: int,
        max_episodes: int = FOREVER,
        behaviour: BehaviourSpec | None = None,
        learning: np.ndarray | None = None,
        with_metrics: bool = True,
        threads: int = 1,
    ) -> np.ndarray:
        """Step until `max_steps` steps or `max_episodes` ended episodes; returns the result fields (R_*).
        Blocks of at least `scale_fast.PARALLEL_MIN` demons learn on `threads` threads."""
        beh_i, beh_f, beh_probs = self._behaviour(behaviour or self.horde.behaviour)
        live = ~self.buf.diverged
        if learning is not None:
            live &= np.asarray(learning, dtype=bool)[self.horde.slot_demon]
        self.buf.alpha_now[:] = np.where(live, self.net.alpha, 0.0)
        self.buf.alpha_w_now[:] = np.where(live, self.net.alpha_w, 0.0)
        self.buf.result[:] = 0.0
        _run(self.net, self.buf, rng, max_steps, max_episodes, beh_i, beh_f, beh_probs, with_metrics, self.onl, threads,
             NO_GIVEN)  # fmt: skip
        return self.buf.result

    # ------------------------------------------------------------------------------------------
    # State in and out

    def _per_demon(self, slots: np.ndarray) -> np.ndarray:
        out = np.empty_like(slots)
        out[self.horde.slot_demon] = slots
        return out

    def rupee(self) -> np.ndarray:
        """[D] RUPEE of every demon, in O(D) (the dot products are kept up to date by the loop)."""
        scale = self.buf.mscale[self.horde.block_group] if len(self.horde.blocks) else np.zeros(0)
        sizes = [b.size for b in self.horde.blocks]
        per_slot = np.repeat(scale, sizes) * self.buf.hu if sizes else np.zeros(0)
        return self._per_demon(np.sqrt(np.abs(per_slot)))

    def ude(self) -> np.ndarray:
        return metrics.ude_of(self._per_demon(self.buf.dstats))

    def thetas(self) -> list[np.ndarray]:
        return [self._weights(self.buf.theta, b).copy() for b in range(len(self.horde.blocks))]

    def step_sizes(self, name: str) -> np.ndarray:
        """[n] one demon's step size of every weight now: per-weight (autostep, tidbd) or alpha (constant)."""
        b, col = self.horde.locate(name)
        slot = int(self.horde.demon_slot[self.horde.index[name]])
        if self.horde.blocks[b].step_size == "constant":
            return np.full(int(self.horde.block_rows[b]), self.net.alpha[slot])
        return self._weights(self.onl.step_a, b)[:, col] * self.onl.ascale[slot]

    def effective_step_sizes(self) -> np.ndarray:
        """[D] the step size each demon takes at the agent's state, in the units of `alpha` (before the division
        by the active count): alpha for a constant step size; the sum of the per-weight step sizes over the
        active features for autostep and tidbd."""
        out = np.zeros(self.horde.num_demons)
        for g, group in enumerate(self.horde.groups):
            active = self.buf.feat[g, : group.coder.k]
            for b in group.blocks:
                block = self.horde.blocks[b]
                lo = int(self.horde.block_lo[b])
                slots = np.arange(lo, lo + block.size)
                if block.step_size == "constant":
                    values = self.net.alpha[slots] * group.coder.k
                else:
                    values = self._weights(self.onl.step_a, b)[active].sum(axis=0) * self.onl.ascale[slots]
                out[self.horde.slot_demon[slots]] = values
        return out

    def horde_state(self, weights_only: bool = False) -> HordeState:
        """A copy of the state in `horde.py`'s form (weights_only: w, e, h and delta_e left empty)."""
        horde, buf = self.horde, self.buf
        blocks = range(len(horde.blocks))
        rest = range(0 if weights_only else len(horde.blocks))
        q = self._per_demon(buf.q)
        q[~horde.is_action_value] = np.nan
        return HordeState(
            theta=tuple(self._weights(buf.theta, b).copy() for b in blocks),
            w=tuple(self._weights(buf.w, b).copy() for b in rest),
            e=tuple(self._traces(b).copy() for b in rest),
            h=tuple(self._weights(buf.h, b).copy() for b in rest),
            delta_e=tuple(self._weights(buf.u, b).copy() for b in rest),
            delta_e_scale=buf.mscale.copy(),
            rupee_dot=self._per_demon(buf.hu),
            tau=buf.tau.copy(),
            delta_stats=self._per_demon(buf.dstats),
            features=tuple(buf.feat[g, : group.coder.k].copy() for g, group in enumerate(horde.groups)),
            class_gamma=buf.class_gamma.copy(),
            class_pi=buf.class_pi.copy(),
            pi=self._per_demon(buf.pi),
            q=q,
            prediction=self._per_demon(buf.pred),
            gamma=self._per_demon(buf.gamma),
            delta=self._per_demon(buf.delta),
            cumulant=self._per_demon(buf.cumulant),
            diverged=self._per_demon(buf.diverged),
        )

    def world_state(self) -> WorldState:
        buf = self.buf
        return WorldState(
            x=buf.pos[:1].copy(), y=buf.pos[1:].copy(), steps=buf.wsteps.copy(), colors=buf.colors[None, :].copy()
        )

    def load(self, state: HordeState, world_state: WorldState) -> None:
        """Copy a `HordeState` (and the first agent of a world state) into the buffers."""
        horde, buf = self.horde, self.buf
        slot = horde.slot_demon
        for b in range(len(horde.blocks)):
            self._weights(buf.theta, b)[:] = state.theta[b]
            self._weights(buf.w, b)[:] = state.w[b]
            self._weights(buf.h, b)[:] = state.h[b]
            self._weights(buf.u, b)[:] = state.delta_e[b]
            e = self._traces(b)
            e[:] = state.e[b]
            rows = np.flatnonzero((e != 0.0).any(axis=1))
            buf.support[self._toff[b] : self._toff[b] + len(rows)] = rows
            buf.nnz[b] = len(rows)
        buf.mscale[:] = state.delta_e_scale
        buf.hu[:] = state.rupee_dot[slot]
        buf.tau[:] = state.tau
        buf.dstats[:] = state.delta_stats[slot]
        for g, group in enumerate(horde.groups):
            buf.feat[g, : group.coder.k] = state.features[g]
        buf.class_gamma[:] = state.class_gamma
        buf.class_pi[:] = state.class_pi
        buf.pi[:] = state.pi[slot]
        buf.q[:] = np.nan_to_num(state.q[slot], nan=0.0)
        buf.q[~horde.is_action_value[slot], 0] = state.prediction[slot][~horde.is_action_value[slot]]
        buf.pred[:] = state.prediction[slot]
        buf.gamma[:] = state.gamma[slot]
        buf.delta[:] = state.delta[slot]
        buf.cumulant[:] = state.cumulant[slot]
        buf.diverged[:] = state.diverged[slot]
        buf.owed[:] = 0.0  # a state's theta owes nothing (the loop pays all before it returns)
        buf.pos[:] = (world_state.x[0], world_state.y[0])
        buf.wsteps[0] = world_state.steps[0]
        buf.colors[:] = world_state.colors[0]

    def observe(self) -> None:
        """Traces to zero, the Horde observes where the agent stands (after a load with new demons)."""
        self.buf.start_sensors[:] = self.buf.sensors
        _observe(self.net, self.buf)
        online_reset(self.net.bi, self.net.reset, self.net.alpha, self.onl)

    # ------------------------------------------------------------------------------------------

    def unique_bytes(self, before: tuple[np.ndarray, ...]) -> int:
        """Bytes of weights and traces that the last step read or wrote, each byte counted once (a model
        of the step's memory traffic; `before`: each group's active features at s_t, taken before the step).

        Per block of Db demons, at 8 bytes a number: theta's whole rows at x_{t+1} (A of them for GQ: read,
        and for GTD / GQ corrected) and on the trace's support (read and written); for GTD / GQ, w's whole
        rows on the support and, for GTD, at x_t; the trace's rows in the support. The learners of
        `adaptive_kernels` (which skip a class whose trace is cut on a row: an upper bound for them): each
        of their per-weight vectors (`VECTORS`) on the same rows as theta. Per-demon vectors (a few numbers
        a demon) are left out."""
        total = 0
        bi, buf = self.net.bi, self.buf
        for g, group in enumerate(self.horde.groups):
            n_s = int(self.net.gi[g, G_NS])
            x_next = np.unique(buf.feat[g, : group.coder.k])
            x_prev = np.unique(before[g])
            for b in group.blocks:
                block = self.horde.blocks[b]
                actions = self.horde.num_actions if block.learner == "gq" else 1
                support = buf.support[int(bi[b, B_TOFF]) :][: int(buf.nnz[b])].astype(np.int64)
                rows = np.union1d(support, np.concatenate([a * n_s + x_next for a in range(actions)])).size
                total += support.size * block.num_classes * buf.trace.itemsize
                if block.learner == "gtd":  # w: on the support and read at x_t (there unless cut)
                    total += 8 * block.size * (rows + np.union1d(support, x_prev).size)
                elif block.learner == "gq":  # x_t's rows (one action's) always stay in the support
                    total += 8 * block.size * (rows + support.size)
                else:
                    total += 8 * block.size * rows * (VECTORS.get(block.learner, 1) + VECTORS.get(block.step_size, 0))
        return total
