"""One learning step for every demon of a Horde, compiled: the transition (s_t, a_t) -> s_{t+1} learned stage by
stage, group by group, block by block (DESIGN sections 4 to 6).

Per group: its stage's question program gives every demon's cumulant, outcome and continuation at s_{t+1}
(`questions.evaluate_nodes`, once per stage); its active features at s_{t+1} are coded (`features.code`); each trace
class's continuation and importance ratio rho_t = pi(a_t | s_t) / b(a_t | s_t) are set; then every block learns with its
learner's kernel (`horde.core.learners`: prepare, columns, finish), a block of at least PARALLEL_MIN demons on `threads`
threads (`columns_on_threads`, the one helper that splits a block's columns, or a TD or GTD block's two halves of rows,
over threads: the same numbers to the last bit whatever the count). Then divergence (`freeze_diverged`, the one rule: a
demon whose TD error, prediction or action values are non-finite or beyond MAX_MAGNITUDE is marked diverged, frozen and
its weights set to 0, so that the demons reading its prediction go on) and RUPEE / UDE.

An episode start (`observe`) zeroes the traces, makes the demons that forget their weights do so, and reads
every demon's values, policy and prediction at the first state. `settle` pays the corrections the gradient
learners owe, before anyone reads theta.

Slots number the demons block by block; everything per demon here is per slot, and the programs' prediction
nodes read slots. The kernels compile without reference counting (`layout.NO_NRT`), but the one parallel
helper, which numba's parallel loops need.
"""

from __future__ import annotations

from numba import njit, prange

from horde.core import learners
from horde.core.engine import metrics
from horde.core.engine.layout import ALIGN, MAX_MAGNITUDE, NO_NRT, PARALLEL_MIN, WITH_NRT, Step
from horde.core.engine.traces import clear
from horde.core.engine.values import read_and_observe, value_policy
from horde.core.features import code
from horde.core.policies import FIXED, OF, UNIFORM
from horde.core.questions import evaluate_nodes

METRICS = -1  # `columns_on_threads`: the metrics' columns, not a learner's
RUN_AT_LEAST = 16  # `continuations_to_slots`: the classes' runs of demons are this long on average, or a look-up each


@njit(cache=True, parallel=True, **WITH_NRT)  # prange allocates: NRT on (a caller without it passes its flag down)
def columns_on_threads(threads, code_, halves, b, lay, wts, dem, cls, onl, met, stp, scr):
    """Block b's columns (its demons) split into runs, each learned by `learners.columns` (code_ a learner's) or
    `metrics.columns` (METRICS) on its own thread; with `halves` = 2, each run of columns walks each half of the
    block's rows on a thread of its own (`learners.half`), threads // 2 runs of columns. Runs start at multiples of
    ALIGN numbers (a cache line) within a row; each demon's numbers come from the same operations in the same order
    whatever the split, so the result does not depend on the count, to the last bit. Every argument is a flat tuple
    of arrays and numbers: numba hands those to its threads."""
    db = lay.block_hi[b] - lay.block_lo[b]
    runs = min(max(1, threads // halves), (db + ALIGN - 1) // ALIGN)
    width = ((db + runs - 1) // runs + ALIGN - 1) // ALIGN * ALIGN
    for t in prange(halves * runs):
        h, run = t // runs, t % runs
        i0 = min(run * width, db)
        i1 = min(i0 + width, db)
        if code_ == METRICS:
            metrics.columns(b, i0, i1, lay, wts, dem, met, stp)
        elif halves == 1:
            learners.columns(code_, b, i0, i1, lay, wts, dem, cls, onl, stp, scr)
        else:
            learners.half(code_, h, b, i0, i1, lay, wts, stp, scr)


@njit(**NO_NRT, inline="always")
def learn_block(b, t, stp, threads):
    """Block b learns the transition with its learner's kernel (see the module)."""
    lay = t.lay
    code_ = lay.learner[b]
    learners.prepare(code_, b, lay, t.wts, t.dem, t.cls, t.onl, stp, t.scr)
    db = lay.block_hi[b] - lay.block_lo[b]
    # (a number at run time: a literal 1 or 2 would compile the parallel helper once for each)
    halves = 2 if learners.walks_in_halves(code_, db) else 1
    if halves == 2:
        learners.before_halves(code_, b, lay, t.wts, t.scr)
    if threads > 1 and db >= PARALLEL_MIN:
        columns_on_threads(threads, code_, halves, b, lay, t.wts, t.dem, t.cls, t.onl, t.met, stp, t.scr)
    elif halves == 2:  # one thread: the halves one after the other, the same operations
        for h in range(2):
            learners.half(code_, h, b, db - db, db, lay, t.wts, stp, t.scr)
    else:  # from db - db: 0 typed int64, as the threads' i0 is (a literal 0 would compile every kernel again)
        learners.columns(code_, b, db - db, db, lay, t.wts, t.dem, t.cls, t.onl, stp, t.scr)
    if halves == 2:
        learners.join_halves(code_, b, lay, t.wts, t.dem, t.cls, stp, t.scr)
    learners.finish(code_, b, lay, t.wts, t.dem, t.cls, t.onl, stp, t.scr)


@njit(**NO_NRT, inline="always")
def learn(t, action, b_prob, terminated, x, y, threads, with_metrics):
    """Every demon learns the transition (s_t, a_t) -> s_{t+1}, with b(a_t | s_t) = b_prob and the sensors of
    s_{t+1} in t.agent.sensors (its position x, y on the grid world), in dependency order (see the module)."""
    grp, progs, dem, cls, coded = t.grp, t.progs, t.dem, t.cls, t.coded
    sensors, values = t.agent.sensors, t.scr.node_values
    current = -1
    for g in range(grp.stage.shape[0]):
        if grp.stage[g] != current:
            current = grp.stage[g]
            evaluate_nodes(progs, current, sensors, dem.pred, values)
        cond = dem.pred[grp.cond[g]] if grp.cond[g] >= 0 else 0.0
        m = code(t.codes, g, x, y, sensors, cond, coded.inputs, coded.taken, coded.next_features, coded.next_values)
        for c in range(grp.class_lo[g], grp.class_hi[g]):
            g1 = min(max(values[progs.class_gnode[c]], 0.0), 1.0) * progs.class_discount[c]
            cls.gamma_tp1[c] = 0.0 if terminated else g1
            cls.rho[c] = cls.pi[c, action] / b_prob
        given_policies(g, grp, progs, dem, cls)
        for s in range(grp.slot_lo[g], grp.slot_hi[g]):
            dem.r[s] = values[progs.out_r[s]]
            dem.z[s] = values[progs.out_z[s]]
        count = coded.counts[g]
        stp = Step(coded.features[g, :count], coded.values[g, :count], coded.next_features[:m],
                   coded.next_values[:m], action, b_prob, grp.n_s[g])  # fmt: skip
        for b in range(grp.block_lo[g], grp.block_hi[g]):
            learn_block(b, t, stp, threads)
        given_to_slots(g, grp, t.lay, dem, cls)
        for c in range(grp.class_lo[g], grp.class_hi[g]):
            for a in range(cls.pi.shape[1]):  # the Horde's actions (a given world may have other than four)
                cls.pi[c, a] = cls.pi_given[c, a]
        continuations_to_slots(g, grp, t.lay, dem, cls)
        if any_diverged(g, grp, t.lay, dem):
            freeze_diverged(g, t, stp)
        if with_metrics:
            group_metrics(g, t, stp, threads)
        for j in range(m):
            coded.features[g, j] = coded.next_features[j]
            coded.values[g, j] = coded.next_values[j]
        coded.counts[g] = m


@njit(**NO_NRT)
def group_metrics(g, t, stp, threads):
    """RUPEE and UDE of group g's demons after their step (`metrics.py`)."""
    lay = t.lay
    metrics.start_group(g, t.grp, lay, t.met)
    for b in range(t.grp.block_lo[g], t.grp.block_hi[g]):
        db = lay.block_hi[b] - lay.block_lo[b]
        if threads > 1 and db >= PARALLEL_MIN:
            columns_on_threads(threads, METRICS, 1, b, lay, t.wts, t.dem, t.cls, t.onl, t.met, stp, t.scr)
        else:  # from db - db: 0 typed int64, as in `learn_block`
            metrics.columns(b, db - db, db, lay, t.wts, t.dem, t.met, stp)


@njit(**NO_NRT)
def observe(t, x, y, sensors):
    """An episode starts at (x, y) with these sensors: demons that forget their weights (reset = "episode") do,
    traces go to zero, and every group reads its demons' values, policies and predictions there. What the
    learners owe is paid first (on the traces and features it is owed on, which this clears)."""
    settle(t)
    lay, grp, dem, cls, coded, wts = t.lay, t.grp, t.dem, t.cls, t.coded, t.wts
    for b in range(lay.learner.shape[0]):
        lo, rows, woff = lay.block_lo[b], lay.rows[b], lay.woff[b]
        db = lay.block_hi[b] - lo
        for i in range(db):
            if lay.reset[lo + i]:
                for row in range(rows):
                    wts.theta[woff + row * db + i] = 0.0
                    wts.w[woff + row * db + i] = 0.0
        clear(b, lay, wts)
    cls.gamma[:] = 0.0
    dem.gamma[:] = 0.0
    for g in range(grp.stage.shape[0]):
        cond = dem.pred[grp.cond[g]] if grp.cond[g] >= 0 else 0.0
        m = code(t.codes, g, x, y, sensors, cond, coded.inputs, coded.taken, coded.features[g], coded.values[g])
        coded.counts[g] = m
        given_policies(g, grp, t.progs, dem, cls)
        for b in range(grp.block_lo[g], grp.block_hi[g]):
            read_and_observe(b, lay, wts, dem, cls, t.scr, coded.features[g, :m], coded.values[g, :m], grp.n_s[g])
        given_to_slots(g, grp, lay, dem, cls)
        for c in range(grp.class_lo[g], grp.class_hi[g]):
            for a in range(cls.pi.shape[1]):  # element by element: a slice copy may allocate
                cls.pi[c, a] = cls.pi_given[c, a]
    learners.episode_start(lay, wts, t.onl)


@njit(**NO_NRT)
def settle(t):
    """Pay every block's owed correction on its group's x_t (`learners.settle`): theta is whole afterwards."""
    grp, coded = t.grp, t.coded
    for g in range(grp.stage.shape[0]):
        m = coded.counts[g]
        for b in range(grp.block_lo[g], grp.block_hi[g]):
            learners.settle(b, t.lay, t.wts, t.scr, coded.features[g, :m], coded.values[g, :m], grp.n_s[g])


@njit(**NO_NRT)
def given_policies(g, grp, progs, dem, cls):
    """pi_given of group g's classes at the state just observed: fixed (or a sign rule's), uniform, or the
    followed slot's current policy."""
    A = cls.pi_given.shape[1]
    for c in range(grp.class_lo[g], grp.class_hi[g]):
        for a in range(A):
            cls.pi_given[c, a] = dem.pi[progs.class_of[c], a] if progs.class_kind[c] == OF else cls.fixed[c, a]


@njit(**NO_NRT)
def given_to_slots(g, grp, lay, dem, cls):
    """Slots of given-policy blocks take their class's policy (a block of own-value demons sets its own). A block's
    demons lie in runs of one class each (`Layout.class_lo`): one policy a run, not one look-up a demon."""
    A = dem.pi.shape[1]
    for b in range(grp.block_lo[g], grp.block_hi[g]):
        if lay.policy[b] != FIXED:
            continue
        lo, coff = lay.block_lo[b], lay.coff[b]
        for c in range(coff, coff + lay.ncls[b]):
            for a in range(A):
                p = cls.pi_given[c, a]
                for s in range(lo + lay.class_lo[c], lo + lay.class_hi[c]):
                    dem.pi[s, a] = p


@njit(**NO_NRT)
def continuations_to_slots(g, grp, lay, dem, cls):
    """Group g's slots after their step: each its class's continuation at s_{t+1} and its cumulant; a class's run of
    demons at a time where the runs are long (`given_to_slots`), else a look-up a demon (a class a demon: GQ's own
    values)."""
    for b in range(grp.block_lo[g], grp.block_hi[g]):
        lo, hi, coff = lay.block_lo[b], lay.block_hi[b], lay.coff[b]
        if lay.ncls[b] * RUN_AT_LEAST > hi - lo:
            for s in range(lo, hi):
                dem.gamma[s] = cls.gamma_tp1[lay.slot_class[s]]
                dem.cumulant[s] = dem.r[s]
            continue
        for c in range(coff, coff + lay.ncls[b]):
            gamma = cls.gamma_tp1[c]
            for s in range(lo + lay.class_lo[c], lo + lay.class_hi[c]):
                dem.gamma[s] = gamma
                dem.cumulant[s] = dem.r[s]


@njit(**NO_NRT)
def apply_rules(rules, sensors, fixed):
    """Target policies of "sign" classes at a state: rules [R, 5] = (class, sensor column, action where
    negative, action where >= 0, epsilon) write (1 - epsilon) on the chosen action plus epsilon / A."""
    A = fixed.shape[1]
    for j in range(rules.shape[0]):
        c = int(rules[j, 0])
        epsilon = rules[j, 4]
        for a in range(A):
            fixed[c, a] = epsilon / A
        chosen = int(rules[j, 3]) if sensors[int(rules[j, 1])] >= 0.0 else int(rules[j, 2])
        fixed[c, chosen] += 1.0 - epsilon


@njit(**NO_NRT)
def behaviour(beh, q, out):
    """b(. | s) of the loop's behaviour into out[:A]: uniform, fixed, or a value policy over a demon's q."""
    A = out.shape[0]
    if beh.kind == UNIFORM:
        for a in range(A):
            out[a] = 1.0 / A
    elif beh.kind == FIXED:
        for a in range(A):
            out[a] = beh.probs[a]
    else:
        value_policy(beh.kind, q[beh.demon], beh.temperature, beh.epsilon, out)


@njit(**NO_NRT)
def slot_diverged(s, action_values, dem):
    """Whether slot s's TD error, prediction or action values are non-finite or beyond MAX_MAGNITUDE."""
    bad = not (abs(dem.delta[s]) <= MAX_MAGNITUDE and abs(dem.pred[s]) <= MAX_MAGNITUDE)  # NaN compares False
    if action_values:
        for a in range(dem.q.shape[1]):
            bad = bad or not abs(dem.q[s, a]) <= MAX_MAGNITUDE
    return bad


@njit(**NO_NRT)
def any_diverged(g, grp, lay, dem):
    """Whether a demon of group g not yet marked has diverged (`slot_diverged`). A block of state values is looked at
    whole, without a branch, so that the check of a step where none has (nearly every step) runs in vector lanes."""
    found = False
    for b in range(grp.block_lo[g], grp.block_hi[g]):
        if lay.actions[b] > 1:
            for s in range(lay.block_lo[b], lay.block_hi[b]):
                found |= slot_diverged(s, True, dem) & (not dem.diverged[s])
            continue
        for s in range(lay.block_lo[b], lay.block_hi[b]):  # `slot_diverged` of a state value, written out
            finite = (abs(dem.delta[s]) <= MAX_MAGNITUDE) & (abs(dem.pred[s]) <= MAX_MAGNITUDE)
            found |= (not finite) & (not dem.diverged[s])
    return found


@njit(**NO_NRT)
def freeze_diverged(g, t, stp):
    """Mark the demons of group g that have diverged (`slot_diverged`); freeze them (step sizes 0) and set their
    weights to 0 (what they had left would sum to nonsense in the demons reading them)."""
    lay, wts, dem = t.lay, t.wts, t.dem
    for b in range(t.grp.block_lo[g], t.grp.block_hi[g]):
        lo, db = lay.block_lo[b], lay.block_hi[b] - lay.block_lo[b]
        found = False
        for i in range(db):
            if dem.diverged[lo + i] or not slot_diverged(lo + i, lay.actions[b] > 1, dem):
                continue
            found = True
            freeze_slot(b, i, lay, wts, dem, t.onl)
        if found:  # read the block's values again with the cleaned weights (the others' owed paid first)
            learners.settle(b, lay, wts, t.scr, stp.x_tp1, stp.v_tp1, stp.n_s)
            read_and_observe(b, lay, wts, dem, t.cls, t.scr, stp.x_tp1, stp.v_tp1, stp.n_s)


@njit(**NO_NRT)
def freeze_slot(b, i, lay, wts, dem, onl):
    """Freeze block b's demon i: marked diverged, step sizes 0, weights 0, nothing owed, and its learner's own
    per-weight step sizes finite (`learners.freeze`: an infinite one would write inf times the frozen rate 0, a
    NaN, into its weights on every later step)."""
    lo, rows, woff = lay.block_lo[b], lay.rows[b], lay.woff[b]
    db, s = lay.block_hi[b] - lo, lo + i
    for a in range(wts.owed.shape[0]):  # its weights are all 0: nothing is owed
        wts.owed[a, s] = 0.0
    dem.diverged[s] = True
    dem.alpha[s] = 0.0
    dem.alpha_w[s] = 0.0
    for row in range(rows):
        wts.theta[woff + row * db + i] = 0.0
        wts.w[woff + row * db + i] = 0.0
    learners.freeze(b, i, lay, onl)
