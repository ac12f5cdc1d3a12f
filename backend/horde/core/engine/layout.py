"""The engine's layout and state: small NamedTuples of arrays with named fields (numba compiles them as structs).

Blocks number the demons ("slots") block by block and their trace classes likewise; groups number the
blocks. What never changes while a Horde learns (`Layout`, `Groups`, `Codes`, `Programs`, `GridWorld`) is
packed once (`pack.py`); what changes (`Weights`, `Demons`, `Classes`, `Coded`, `Metrics`, `Online`, `Agent`) the
kernels update in place; `Scratch` is working space; `Step` is one transition as a group sees it.

Every NamedTuple is flat (arrays and numbers, no tuple inside another): numba passes flat tuples to the
threads of a parallel loop (`step.columns_on_threads`), nested ones not. Weights are feature-major: block
b's weights are `[rows_b, Db]` row-major at `woff[b]` of the flat `theta`; its traces `[rows_b, C_b]` at
`voff[b]` of `trace`, zero off the support, whose rows (sorted) are at `toff[b]` of `support`.

Features are sparse with values: a state's active features are `count` distinct sorted indices, each with
its value. Binary features (value 1) stay the fast special case without a path of their own: a kernel
multiplies by the value, and multiplying by 1 is exact, so binary features give the same numbers, bit for
bit, as kernels that add rows; where a loop is bound by its arithmetic (a row just written, read again), a
value of 1 skips the multiplication (`rows.add_row`). Measured: docs/performance.md, "Engine as modules".
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

# The kernels' compile options: cached, without reference counting. numba takes and gives back a count of
# every array passed to a compiled function (an atomic add each); the kernels allocate nothing and keep no
# array past the call, so the count buys nothing (it was 44% of a thesis-scale step, docs/performance.md).
# A kernel compiled so cannot allocate, and passes the setting down unless the callee sets `_nrt=True`.
# numba's type stubs do not list `_nrt`, hence the dicts.
NO_NRT: dict[str, Any] = {"cache": True, "_nrt": False}
WITH_NRT: dict[str, Any] = {"_nrt": True}
PARALLEL_MIN = 512  # demons of a block from which its columns are split over threads
ALIGN = 8  # column runs start at multiples of 8 numbers (64 bytes, a cache line) within a row
# Beyond this, in absolute value, a demon's TD error, prediction, action values or weights mean nothing any more
# (a diverging GQ demon reached 1.6e307 before its numbers overflowed): the demon is marked diverged and frozen.
MAX_MAGNITUDE = 1e12
FOREVER = 2**62  # "no limit" for step and episode counts
OWED_ROWS = 5  # rows of `Weights.owed` at least (GTD's five numbers a demon owes, `learners.gtd_pass`)
EV_ROWS = 36  # rows of `Scratch.ev` (`learners.gtd_pass`: what is owed in the weights' dtype, and 2 x 16 cells)


class Layout(NamedTuple):
    """The blocks, their demons (slots) and trace classes: constant while the Horde learns."""

    learner: np.ndarray  # [B] the learner's kernel code (`horde.core.learners.KERNELS`)
    policy: np.ndarray  # [B] FIXED (target policies given per class) or an own-value kind (GQ)
    block_lo: np.ndarray  # [B] first slot of the block
    block_hi: np.ndarray  # [B] one past its last
    actions: np.ndarray  # [B] its action blocks: A for action values (GQ), 1 for state values
    rows: np.ndarray  # [B] weight rows: actions * n_s
    woff: np.ndarray  # [B] offset of its [rows, Db] weights in the flat buffers
    toff: np.ndarray  # [B] offset of its support rows
    voff: np.ndarray  # [B] offset of its [rows, C_b] traces
    ncls: np.ndarray  # [B] its trace classes
    coff: np.ndarray  # [B] its first (global) trace class
    lam: np.ndarray  # [B] lambda
    group: np.ndarray  # [B] its group
    owes: np.ndarray  # [B] bool: its learner owes its correction at x_{t+1} to the next step (`learners.settle`)
    alpha: np.ndarray  # [D] per slot, divided by the active count
    alpha_w: np.ndarray  # [D] of the secondary weights (tdrc: of h)
    beta: np.ndarray  # [D] tdrc: the regularisation of h (0 elsewhere)
    temperature: np.ndarray  # [D] softmax target policies
    epsilon: np.ndarray  # [D] epsilon-greedy target policies
    reset: np.ndarray  # [D] bool: forget the weights at every episode start
    slot_class: np.ndarray  # [D] global trace class of each slot
    class_lo: np.ndarray  # [C] first slot of each class, within its block
    class_hi: np.ndarray  # [C] one past its last
    cut: float  # the trace cut (0 keeps every non-zero entry)


class Groups(NamedTuple):
    """The groups (demons of one stage over one feature set) as the step walks them."""

    stage: np.ndarray  # [G] the stage whose question program it reads
    n_s: np.ndarray  # [G] state features (all condition blocks included)
    k: np.ndarray  # [G] its active count (alpha and RUPEE's step of h are divided by it)
    cond: np.ndarray  # [G] slot of the condition demon, or -1
    block_lo: np.ndarray  # [G] its blocks
    block_hi: np.ndarray
    class_lo: np.ndarray  # [G] its trace classes
    class_hi: np.ndarray
    slot_lo: np.ndarray  # [G] its slots
    slot_hi: np.ndarray


class Codes(NamedTuple):
    """How each group codes a state into active features (`horde.core.features.code`): one entry per group."""

    kind: np.ndarray  # [G] the feature kind's code (`features.FEATURE_KINDS`)
    parts: np.ndarray  # [G] stripes: parts
    tilings: np.ndarray  # [G] tiles, sensors: offset tilings
    tiles: np.ndarray  # [G] tiles, grid, sensors: tiles per dimension
    base_n: np.ndarray  # [G] state features of one condition block
    width: np.ndarray  # [G] rbf: sigma, in units of the scaled inputs
    thr_lo: np.ndarray  # [G] its condition's thresholds in `thresholds`
    thr_hi: np.ndarray
    sensor_lo: np.ndarray  # [G] the sensors it reads (tiled, or a basis' inputs) in `sensor_col`
    sensor_hi: np.ndarray
    table_at: np.ndarray  # [G] table: its rows' offset in `table` and `table_values`
    table_rows: np.ndarray  # [G] table: its rows
    table_width: np.ndarray  # [G] table: the entries of a row
    table_col: np.ndarray  # [G] table: the sensor column whose reading picks a row
    basis_at: np.ndarray  # [G] polynomial / fourier / rbf: its rows in `basis` (exponents, or centres)
    basis_rows: np.ndarray  # [G] its features
    thresholds: np.ndarray  # conditioned features' thresholds
    sensor_col: np.ndarray  # a sensor column
    sensor_low: np.ndarray  # and the range it is scaled from
    sensor_high: np.ndarray
    table: np.ndarray  # every table's rows of indices, flat
    table_values: np.ndarray  # and their values
    basis: np.ndarray  # [rows, most inputs] polynomial / fourier exponents, rbf centres
    plane_width: float  # positions x / width and y / height (the grid world's size; 1 elsewhere)
    plane_height: float


class Programs(NamedTuple):
    """The stages' question programs in one node table (`questions.Program.table`); prediction nodes read slots."""

    stage_lo: np.ndarray  # [S] first node of each stage's program
    stage_hi: np.ndarray
    node_kind: np.ndarray  # [N] questions.NODE_KINDS
    node_arg: np.ndarray  # [N] sensor column, prediction slot or constant
    node_start: np.ndarray  # [N + 1] children of node n: node_children[node_start[n]:node_start[n + 1]]
    node_children: np.ndarray
    out_r: np.ndarray  # [D] node of each slot's cumulant
    out_z: np.ndarray  # [D] node of each slot's outcome
    class_gnode: np.ndarray  # [C] node of each class's continuation
    class_discount: np.ndarray  # [C]
    class_kind: np.ndarray  # [C] UNIFORM / FIXED / OF, or the kind of an own-value demon
    class_of: np.ndarray  # [C] slot followed, or -1


class GridWorld(NamedTuple):
    """The grid world (`world.World`) as the compiled loop reads it."""

    width: float
    height: float
    step: float
    slip: float
    noise: float
    transient: float
    max_steps: float
    start_rect: bool  # start is a rectangle [x0, y0, x1, y1] to draw from (else the point start[:2])
    start: np.ndarray  # [4]
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


class Weights(NamedTuple):
    """Every block's weights and traces, flat (offsets in `Layout`)."""

    theta: np.ndarray  # primary weights, blocks' [rows, Db] at woff
    w: np.ndarray  # secondary weights (gradient corrections; tdrc's h, kept scaled; adaptive TD's h)
    trace: np.ndarray  # blocks' [rows, C_b] at voff
    support: np.ndarray  # blocks' sorted support rows at toff
    support_f: np.ndarray  # x_t's value on each support row at the last merge (`learners.gtd_pass`; float64)
    nnz: np.ndarray  # [B] support rows of each block
    touched: np.ndarray  # [B] support rows after the last step
    owed: np.ndarray  # [max(A, 5), D] what the last step left owed: GQ's correction at x_{t+1} per action
    # (`learners.gradient`), TD's alpha delta (`td_pass`), GTD's five numbers (`gtd_pass.OWED_*`)


class Demons(NamedTuple):
    """Per slot: what a step reads and writes."""

    alpha: np.ndarray  # [D] the step size now (0 where frozen: diverged, or not learning in a test run)
    alpha_w: np.ndarray  # [D]
    r: np.ndarray  # [D] cumulant at s_{t+1}
    z: np.ndarray  # [D] outcome at s_{t+1}
    pi: np.ndarray  # [D, A] target policy at s_t
    q: np.ndarray  # [D, A] action values at s_t (column 0: the value of a state-value demon)
    pred: np.ndarray  # [D] prediction at s_t
    gamma: np.ndarray  # [D] continuation at s_t
    delta: np.ndarray  # [D] the last TD error
    cumulant: np.ndarray  # [D] the last cumulant
    diverged: np.ndarray  # [D] bool: frozen since its numbers went beyond MAX_MAGNITUDE


class Classes(NamedTuple):
    """Per trace class: what its shared trace reads."""

    gamma: np.ndarray  # [C] continuation at s_t
    gamma_tp1: np.ndarray  # [C] at s_{t+1}
    rho: np.ndarray  # [C] pi(a_t | s_t) / b(a_t | s_t)
    pi: np.ndarray  # [C, A] target policy at s_t (own-value classes: unused)
    pi_given: np.ndarray  # [C, A] at s_{t+1}
    fixed: np.ndarray  # [C, A] a given policy's probabilities (sign rules rewrite them at every state)


class Coded(NamedTuple):
    """Each group's active features at s_t, and one group's at s_{t+1}."""

    features: np.ndarray  # [G, kmax] at s_t, sorted and distinct
    values: np.ndarray  # [G, kmax]
    counts: np.ndarray  # [G]
    next_features: np.ndarray  # [kmax] at s_{t+1}
    next_values: np.ndarray  # [kmax]
    next_count: np.ndarray  # [1]
    inputs: np.ndarray  # [most sensors of a group] scratch: a group's sensors, scaled
    taken: np.ndarray  # [most state features of a group] uint8 scratch of zeros: `features.hashed_tiles`'s marks


class Metrics(NamedTuple):
    """RUPEE and UDE (`metrics.py`), with the average of delta e scaled lazily per group."""

    h: np.ndarray  # RUPEE's h, as theta
    u: np.ndarray  # RUPEE's average of delta e, divided by `scale` of its group
    hu: np.ndarray  # [D] sum over rows of h * u, kept up to date (RUPEE = sqrt(|scale hu|))
    scale: np.ndarray  # [G]
    tau: np.ndarray  # [G, 2] the unbiased-start weights of RUPEE and UDE
    stats: np.ndarray  # [D, 3] averages of delta, delta^2 and |delta|
    hx: np.ndarray  # [2 dmax] scratch: h . x_t and delta of a block's demons
    coef: np.ndarray  # [3] scratch: a group's step of h, gain of delta e into u, UDE's rate (`metrics.start_group`)


class Online(NamedTuple):
    """What the learners beyond the gradient family keep (slots and classes global)."""

    v_old: np.ndarray  # [D] true online: theta_{t-1} . x_t
    cls_alpha: np.ndarray  # [C] the alpha of a true online class's dutch trace
    cls_beta: np.ndarray  # [C] true online GTD: alpha_w of the class's w trace
    cls_f: np.ndarray  # [C] emphatic TD's followon trace
    cls_rho_prev: np.ndarray  # [C] rho_{t-1}
    trace2: np.ndarray  # true online GTD: per block [2, rows, C_b] at 2 voff: e_grad, then e_w
    support2: np.ndarray  # true online GTD: per block at toff, the sorted rows where e_grad or e_w is non-zero
    nnz2: np.ndarray  # [B] how many
    w_read: np.ndarray  # [3, D] true online GTD: w . e_grad_{t-1}, w . x_t (the last w pass read them), w . e_grad_t;
    # TIDBD (h in w): [0] the largest |phi h| over x_t's rows, which the last walk read at x_tp1 (`adaptive`)
    w_read_ok: np.ndarray  # [B] 1 where the last step's w pass left w_read for this step (0: read it afresh)
    step_a: np.ndarray  # adaptive TD: per-weight step sizes, as theta (before the scale)
    step_v: np.ndarray  # autostep's normaliser v, as theta
    scale: np.ndarray  # [D] a demon's lazily kept scale: adaptive TD's step sizes (step_a times it), tdrc's h (w)
    step_max: np.ndarray  # [D] float64: at least each Autostep demon's largest stored step size (inf: not counted)
    meta: np.ndarray  # [D] mu (autostep) or theta (tidbd)
    tau: float  # autostep's tau
    bounds: np.ndarray  # [max C_b + 1] int: the first demon of each class of a block, then Db


class Agent(NamedTuple):
    """The agent in the grid world (or the sensors of a world fed from outside) and the last step's result."""

    pos: np.ndarray  # [2]
    steps: np.ndarray  # [1] transitions so far in the episode
    colors: np.ndarray  # [I] colour of each indicator
    sensors: np.ndarray  # [S] at the last s_{t+1}
    start_sensors: np.ndarray  # [S] at the state the Horde last observed afresh (an episode's first state)
    returns: np.ndarray  # [2] this episode's return so far, the last episode's
    result: np.ndarray  # [8] the loop's R_* fields
    inside: np.ndarray  # [R] bool scratch: regions holding the agent
    cdf: np.ndarray  # [A] scratch: the behaviour's cumulative probabilities
    probs: np.ndarray  # [A] scratch: the behaviour's probabilities


class Scratch(NamedTuple):
    """Working space of a step (per block, per demon of the largest block)."""

    node_values: np.ndarray  # [N] the question programs' node values
    rows: np.ndarray  # [most rows of a block + kmax] the merged support, then the rows of x_t left without trace
    rows_e: np.ndarray  # the one-class trace value on each merged row
    rows_f: np.ndarray  # x_t's value on each merged row
    rows_left: np.ndarray  # int8: whether any trace is left on each merged row (GQ's own-value pass sets it)
    values: np.ndarray  # [A, dmax] values of a block's demons at s_{t+1}
    pi_next: np.ndarray  # [A, dmax] their target policies there
    work: np.ndarray  # [8, dmax] per demon: alpha delta, alpha_w delta, w . e, w . x_t, and learners' own
    scales: np.ndarray  # [3, dmax] per demon, how w is kept (1 but for tdrc): w's step, w . x_t's, w . e's factor
    decay: np.ndarray  # [max C_b] each class's trace decay
    add: np.ndarray  # [max C_b] what x_t adds to each class's trace
    mark: np.ndarray  # [most rows] x_bar's value on a row at s_{t+1} (GQ's support pass; else 0)
    counts: np.ndarray  # [2] int: the support rows kept and x_t's rows dropped by the block's last merge
    ex: np.ndarray  # [A, dmax] e . x_bar(s_{t+1}, a) per demon
    ev: np.ndarray  # [EV_ROWS, dmax] in the weights' dtype: a support row's trace values spread over the demons (GQ),
    # what is owed as the one-pass kernels pay it (`td_pass`, `gtd_pass`)
    sums: np.ndarray  # [6, dmax] in the weights' dtype: `gtd_pass`'s sums over a few rows, of each half (float64:
    # work[1:7] itself)


class Step(NamedTuple):
    """One transition as a group's blocks see it."""

    x_t: np.ndarray  # [m] active state features at s_t (sorted, distinct)
    v_t: np.ndarray  # [m] their values
    x_tp1: np.ndarray  # [m'] at s_{t+1}
    v_tp1: np.ndarray  # [m']
    action: int  # a_t
    b_prob: float  # b(a_t | s_t)
    n_s: int  # the group's state features (action a's block starts at row a * n_s)


class Behaviour(NamedTuple):
    """The behaviour policy of the grid world's loop: uniform, fixed, or over a control demon's action values."""

    kind: int  # policies.UNIFORM, FIXED, GREEDY, SOFTMAX or EPSILON_GREEDY
    demon: int  # the control demon's slot (value policies), else -1
    temperature: float
    epsilon: float
    probs: np.ndarray  # [A] a fixed behaviour's probabilities


class Given(NamedTuple):
    """Transitions observed outside the grid world (`horde.core.learner`), learned in order in place of the
    world's moves: row t is s_t, a_t -> s_{t+1} with s_{t+1}'s sensors. An empty `sensors`: the grid world."""

    sensors: np.ndarray  # [T, S] the sensors of s_{t+1}
    actions: np.ndarray  # [T] a_t
    b_probs: np.ndarray  # [T] b(a_t | s_t)
    terminated: np.ndarray  # [T] bool: s_{t+1} is terminal (only the last row may be)
    rules: np.ndarray  # [R, 5] the target policies of "sign" classes (`step.apply_rules`)
    pred_out: np.ndarray  # [T, D] the predictions (slot order) after each row, or [0, D] to keep none


NO_GIVEN = Given(np.zeros((0, 1)), np.zeros(0, np.int64), np.zeros(0), np.zeros(0, np.bool_), np.zeros((0, 5)),
                 np.zeros((0, 1)))  # fmt: skip


class Tables(NamedTuple):
    """Every table of an engine, for its compiled step and loop (nested: never handed to threads whole)."""

    lay: Layout
    grp: Groups
    codes: Codes
    progs: Programs
    world: GridWorld
    wts: Weights
    dem: Demons
    cls: Classes
    coded: Coded
    met: Metrics
    onl: Online
    scr: Scratch
    agent: Agent
