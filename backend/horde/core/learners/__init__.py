"""The learners: one module per learner family, each with its registration, its readable numpy form and its
compiled kernel for the engine.

* `gradient`: GQ(lambda), GTD(lambda), off-policy TD(lambda) (GQ's kernel; TD's is `td_pass`, GTD's `gtd_pass`);
* `true_online`: true online TD(lambda) (its walk `td_pass.walk`), true online GTD(lambda);
* `emphatic`: emphatic TD(lambda) (TD's kernel `td_pass`, the emphasis in its trace);
* `adaptive`: TD(lambda) with Autostep / TIDBD step sizes;
* `tdrc`: TD with regularized corrections (GTD's kernel `gtd_pass`, h kept scaled);
* `gtd2`: GTD2(lambda) and the original GTD (lambda = 0): GTD's kernel, theta following the secondary weights.

Importing this package registers every learner with the spec (`horde.spec.learners`), so that a demon may
name it, the API lists it (`GET /api/learners`) and the dashboard offers it. A learner module declares
`register(LearnerInfo(...))` (the spec's view: name, text, parameters, needs) and `KERNELS` (the engine's
view: one `Kernel` per code, `base.Kernel`), and has `prepare`, `columns` and `finish`, which the engine's
step calls through the dispatchers below for every block of that learner:

* `prepare(...)`: before the block's columns, what is shared by its demons: each class's trace decay and what
  x_t adds, the trace merge (`engine.traces.merge`), whatever else the block does once;
* `columns(..., b, i0, i1, ...)`: demons i0 <= i < i1 learn the transition, touching only their columns (a
  block of at least `PARALLEL_MIN` demons splits them over threads: `engine.step.columns_on_threads`), and
  store their values, policies and predictions at s_{t+1}; a learner may instead walk a wide block's rows in two
  halves (`walks_in_halves`, `half`, `join_halves`: TD's, `td_pass`, and GTD's, `gtd_pass`), each half taking every
  column;
* `finish(...)`: after every column learned (each class's continuation moves to s_{t+1}).

A new learner is a new module (and its tests and oracle function in `reference.py`), imported here and
dispatched on by its code below.
"""

from numba import njit

from horde.core.engine.layout import NO_NRT
from horde.core.learners import adaptive, emphatic, gradient, gtd2, gtd_pass, online, td_pass, tdrc, true_online
from horde.core.learners.adaptive import adaptive_td_update
from horde.core.learners.base import Kernel, OnlineState, online_zeros
from horde.core.learners.emphatic import etd_update
from horde.core.learners.gradient import LearnerParams, LearnerState, dot_sparse, update, zeros
from horde.core.learners.gtd2 import gtd1_update, gtd2_update
from horde.core.learners.gtd_pass import FOLLOWS_DELTA, FOLLOWS_U, FOLLOWS_W
from horde.core.learners.tdrc import tdrc_update
from horde.core.learners.true_online import true_online_gtd_update, true_online_td_update

FAMILIES = (gradient, true_online, emphatic, adaptive, tdrc, gtd2)
KERNELS: dict[int, Kernel] = {k.code: k for m in FAMILIES for k in m.KERNELS}
assert len(KERNELS) == sum(len(m.KERNELS) for m in FAMILIES), "two kernels have one code"
GQ_CODE, GTD_CODE, TD_CODE = gradient.GQ_CODE, gradient.GTD_CODE, gradient.TD_CODE
TOTD_CODE, TOGTD_CODE, ETD_CODE = true_online.TOTD_CODE, true_online.TOGTD_CODE, emphatic.ETD_CODE
TIDBD_CODE, AUTOSTEP_CODE, TDRC_CODE = adaptive.TIDBD_CODE, adaptive.AUTOSTEP_CODE, tdrc.TDRC_CODE
GTD2_CODE, GTD1_CODE = gtd2.GTD2_CODE, gtd2.GTD1_CODE


def kernel_for(learner: str, step_size: str = "constant") -> Kernel:
    """The kernel that learns `learner` with `step_size`.

    Raises:
        ValueError: no kernel learns that combination (the spec refuses it first: `step_size_problem`).
    """
    for kernel in KERNELS.values():
        if kernel.learner == learner and kernel.step_size == step_size:
            return kernel
    raise ValueError(f"no kernel learns {learner!r} with step size {step_size!r}")


@njit(**NO_NRT, inline="always")
def prepare(code, b, lay, wts, dem, cls, onl, stp, scr):
    """Block b's shared work before its columns (see the module)."""
    if code == TD_CODE:
        td_pass.prepare(b, lay, cls, scr)
    elif code in (GTD_CODE, TDRC_CODE, GTD2_CODE, GTD1_CODE):  # TDRC's h, GTD1's u kept scaled (`tdrc`)
        gtd_pass.prepare(b, lay, dem, cls, onl, scr, code in (TDRC_CODE, GTD1_CODE))
    elif code == GQ_CODE:
        gradient.prepare(b, lay, wts, dem, cls, stp, scr)
    elif code in (TOTD_CODE, TOGTD_CODE):
        true_online.prepare(code, b, lay, wts, dem, cls, onl, stp, scr)
    elif code == ETD_CODE:
        emphatic.prepare(b, lay, cls, onl, scr)
    else:
        adaptive.prepare(code, b, lay, wts, cls, onl, stp, scr)


@njit(**NO_NRT, inline="always")
def _gtd_form(code):
    """What theta follows in GTD's kernel (`gtd_pass`) for this learner. (A number at run time: numba compiles a copy
    of a function for each literal argument.)"""
    return FOLLOWS_W if code == GTD2_CODE else FOLLOWS_U if code == GTD1_CODE else FOLLOWS_DELTA


@njit(**NO_NRT, inline="always")
def columns(code, b, i0, i1, lay, wts, dem, cls, onl, stp, scr):
    """Block b's demons i0 <= i < i1 learn the transition (see the module)."""
    if code in (TD_CODE, ETD_CODE):  # emphatic TD is TD's kernel with the emphasis in its trace (`emphatic`)
        td_pass.columns(b, i0, i1, lay, wts, dem, cls, stp, scr)
    elif code in (GTD_CODE, TDRC_CODE, GTD2_CODE, GTD1_CODE):
        gtd_pass.columns(b, i0, i1, lay, wts, dem, cls, stp, scr, _gtd_form(code))
    elif code == GQ_CODE:
        gradient.columns(b, i0, i1, lay, wts, dem, cls, stp, scr)
    elif code in (TOTD_CODE, TOGTD_CODE):
        true_online.columns(code, b, i0, i1, lay, wts, dem, cls, stp, scr, onl)
    else:
        adaptive.columns(code, b, i0, i1, lay, wts, dem, cls, onl, stp, scr)


@njit(**NO_NRT, inline="always")
def walks_in_halves(code, db):
    """Whether a block of this learner and db demons walks its rows in two halves (`half`, each on a thread of its
    own when there are two), not its columns split: the wide blocks of TD and emphatic TD (`td_pass`) and of GTD's
    kernel (`gtd_pass`)."""
    return code in (TD_CODE, ETD_CODE, GTD_CODE, TDRC_CODE, GTD2_CODE, GTD1_CODE) and td_pass.walks_in_halves(db)


@njit(**NO_NRT, inline="always")
def before_halves(code, b, lay, wts, scr):
    """A block that walks in halves: what both halves need first (what is owed, in the weights' dtype; GTD's: and
    both halves' sums at 0)."""
    if code in (TD_CODE, ETD_CODE):
        td_pass.owed_to_pay(b, 0, lay.block_hi[b] - lay.block_lo[b], lay, wts, scr, False)
    else:
        gtd_pass.before_halves(b, lay, wts, scr)


@njit(**NO_NRT, inline="always")
def half(code, h, b, i0, i1, lay, wts, stp, scr):
    """Block b's demons i0 <= i < i1 walk half h (0 or 1) of the block's rows."""
    if code in (TD_CODE, ETD_CODE):
        td_pass.walk_half(h, b, i0, i1, lay, wts, stp, scr)
    else:
        gtd_pass.walk_half(h, b, i0, i1, lay, wts, stp, scr, _gtd_form(code))


@njit(**NO_NRT, inline="always")
def join_halves(code, b, lay, wts, dem, cls, stp, scr):
    """After both halves: the two halves' sums added in order, then the TD errors (and what GTD's kernel owes)."""
    if code in (TD_CODE, ETD_CODE):
        td_pass.join_halves(b, lay, wts, dem, cls, scr)
    else:
        gtd_pass.join_halves(b, lay, wts, dem, cls, stp, scr, _gtd_form(code))


@njit(**NO_NRT, inline="always")
def finish(code, b, lay, wts, dem, cls, onl, stp, scr):
    """Block b after every column learned (see the module)."""
    if code in (TD_CODE, ETD_CODE, TOTD_CODE):
        td_pass.finish(b, lay, wts, dem, cls, stp, scr, code == TOTD_CODE)
        if code == ETD_CODE:  # its next followon reads rho_{t-1}
            online.keep_rho(b, lay, cls, onl)
    elif code in (GTD_CODE, TDRC_CODE, GTD2_CODE, GTD1_CODE):
        gtd_pass.finish(b, lay, wts, dem, cls, onl, stp, scr, code in (TDRC_CODE, GTD1_CODE))
    elif code == GQ_CODE:
        gradient.finish(b, lay, wts, cls, stp, scr)
    else:
        online.finish(b, lay, cls, onl)


@njit(**NO_NRT)
def settle(b, lay, wts, scr, x, v, n_s):
    """Pay what block b owes (TD, emphatic TD, true online TD: its last update, `td_pass`; GTD, TDRC, GTD2, GTD1:
    theirs, `gtd_pass`, with the rows x of the last x_{t+1}, values v; GQ: its correction at the last x_{t+1},
    `gradient.columns`), so that theta and w can be read whole."""
    code = lay.learner[b]
    if code in (TD_CODE, ETD_CODE, TOTD_CODE):
        td_pass.settle(b, lay, wts, scr, code == TOTD_CODE)
    elif code in (GTD_CODE, TDRC_CODE, GTD2_CODE, GTD1_CODE):
        gtd_pass.settle(b, lay, wts, x, v)
    elif lay.owes[b]:
        gradient.settle_owed(b, lay, wts, x, v, n_s)


@njit(**NO_NRT)
def freeze(b, i, lay, onl):
    """Block b's demon i is frozen (`step.freeze_slot`): the learners that keep per-weight step sizes set its to 0
    (`adaptive.freeze`)."""
    adaptive.freeze(b, i, lay, onl)


@njit(**NO_NRT)
def episode_start(lay, wts, onl):
    """An episode starts: the learners that keep state beyond the weights restart it where a demon forgets its
    weights (`adaptive.reset`, `tdrc.episode_start`: TDRC's h and the original GTD's u are kept scaled)."""
    adaptive.reset(lay, onl)
    tdrc.episode_start(TDRC_CODE, GTD1_CODE, lay, onl)
    true_online.episode_start(onl)


__all__ = [
    "KERNELS",
    "Kernel",
    "LearnerParams",
    "LearnerState",
    "OnlineState",
    "adaptive",
    "adaptive_td_update",
    "columns",
    "dot_sparse",
    "emphatic",
    "episode_start",
    "etd_update",
    "finish",
    "gradient",
    "gtd1_update",
    "gtd2",
    "gtd2_update",
    "gtd_pass",
    "kernel_for",
    "online_zeros",
    "prepare",
    "settle",
    "tdrc",
    "tdrc_update",
    "true_online",
    "true_online_gtd_update",
    "true_online_td_update",
    "update",
    "zeros",
]
