"""A compiled `Horde` and its world packed into the engine's tables (`layout.py`), fresh: weights at their start.

Why about 260 lines: one function per table, each building its named arrays field by field (one array a line,
its shape read where it is made).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from horde.core.engine.blocks import POLICY_CODES
from horde.core.engine.layout import (
    EV_ROWS,
    OWED_ROWS,
    Agent,
    Classes,
    Coded,
    Demons,
    GridWorld,
    Groups,
    Layout,
    Metrics,
    Online,
    Programs,
    Scratch,
    Tables,
    Weights,
)
from horde.core.features import CodeEntry, pack_codes
from horde.core.horde import Horde
from horde.core.questions import N_PREDICTION
from horde.core.world import World
from horde.spec import WorldSpec


class Offsets(NamedTuple):
    """Where each block's arrays start in the flat buffers ([B + 1] each, the last the total)."""

    weights: np.ndarray  # of [rows, Db] weights
    support: np.ndarray  # of its support rows
    traces: np.ndarray  # of [rows, C_b] traces


def offsets(horde: Horde) -> Offsets:
    rows = horde.block_rows
    sizes = np.array([b.size for b in horde.blocks], dtype=np.int64)
    ncls = np.array([b.num_classes for b in horde.blocks], dtype=np.int64)
    return Offsets(
        np.cumsum([0, *(rows * sizes)]).astype(np.int64),
        np.cumsum([0, *rows]).astype(np.int64),
        np.cumsum([0, *(rows * ncls)]).astype(np.int64),
    )


def pack(horde: Horde, world: World | None) -> Tables:
    """Every table of the engine for a compiled Horde (and its grid world; None: a world fed from outside).

    Why 65 lines: the small tables are built here field by field, one array a line."""
    off = offsets(horde)
    lay = _layout(horde, off)
    progs = _programs(horde)
    scr = _scratch(horde, lay, len(progs.node_kind))
    kmax = max((g.coder.k for g in horde.groups), default=1)
    sensors = len(horde.plan.sensors)
    dtype = horde.dtype  # of every per-weight array (weights, traces, RUPEE's, the adaptive learners')
    wts = Weights(
        theta=np.zeros(int(off.weights[-1]), dtype),
        w=np.zeros(int(off.weights[-1]), dtype),
        trace=np.zeros(int(off.traces[-1]), dtype),
        support=np.zeros(int(off.support[-1]), np.int64),
        support_f=np.zeros(int(off.support[-1])),
        nnz=np.zeros(len(horde.blocks), np.int64),
        touched=np.zeros(len(horde.blocks), np.int64),
        owed=np.zeros((max(horde.num_actions, OWED_ROWS), horde.num_demons)),
    )
    for b, theta in enumerate(horde.initial_theta()):  # demons with initial_weights start from them
        wts.theta[off.weights[b] : off.weights[b + 1]] = theta.ravel()
    return Tables(
        lay=lay,
        grp=_groups(horde),
        codes=pack_codes(
            [CodeEntry(g.coder.spec, list(horde.plan.sensors), horde.plan.bounds) for g in horde.groups],
            horde.plan.plane,
        ),
        progs=progs,
        world=_world(world if world is not None else World(WorldSpec())),
        wts=wts,
        dem=_demons(horde, lay),
        cls=_classes(horde),
        coded=Coded(
            features=np.zeros((len(horde.groups), kmax), np.int64),
            values=np.zeros((len(horde.groups), kmax)),
            counts=np.zeros(len(horde.groups), np.int64),
            next_features=np.zeros(kmax, np.int64),
            next_values=np.zeros(kmax),
            next_count=np.zeros(1, np.int64),
            inputs=np.zeros(max([1, *(len(g.coder.spec.sensors or []) for g in horde.groups)])),
            taken=np.zeros(max([1, *(g.coder.base_n for g in horde.groups)]), np.uint8),
        ),
        met=Metrics(
            h=np.zeros(int(off.weights[-1]), dtype),
            u=np.zeros(int(off.weights[-1]), dtype),
            hu=np.zeros(horde.num_demons),
            scale=np.ones(len(horde.groups)),
            tau=np.zeros((len(horde.groups), 2)),
            stats=np.zeros((horde.num_demons, 3)),
            hx=np.zeros(2 * scr.work.shape[1]),
            coef=np.zeros(3),
        ),
        onl=_online(horde, lay, off),
        scr=scr,
        agent=Agent(
            pos=np.zeros(2),
            steps=np.zeros(1, np.int64),
            colors=np.zeros(world.num_indicators if world is not None else 0, np.int64),
            sensors=np.zeros(sensors),
            start_sensors=np.zeros(sensors),
            returns=np.zeros(2),
            result=np.zeros(8),
            inside=np.zeros(len(world.rects) if world is not None else 0, np.bool_),
            cdf=np.zeros(horde.num_actions),
            probs=np.zeros(horde.num_actions),
        ),
    )


def _layout(horde: Horde, off: Offsets) -> Layout:
    blocks = horde.blocks
    sizes = np.array([b.size for b in blocks], dtype=np.int64)
    ncls = np.array([b.num_classes for b in blocks], dtype=np.int64)
    starts = [np.searchsorted(np.asarray(b.classes), np.arange(b.num_classes)) for b in blocks]
    ends = [np.searchsorted(np.asarray(b.classes), np.arange(b.num_classes), side="right") for b in blocks]

    def per_slot(name: str) -> np.ndarray:
        return np.concatenate([np.asarray(getattr(b, name), dtype=float) for b in blocks]) if blocks else np.zeros(0)

    return Layout(
        learner=np.array([b.code for b in blocks], dtype=np.int64),
        policy=np.array([POLICY_CODES[b.policy] for b in blocks], dtype=np.int64),
        block_lo=horde.block_lo.astype(np.int64),
        block_hi=(horde.block_lo + sizes).astype(np.int64),
        actions=np.array(
            [horde.num_actions if horde.groups[g].action_values else 1 for g in horde.block_group], dtype=np.int64
        ),
        rows=horde.block_rows.astype(np.int64),
        woff=off.weights[:-1].copy(),
        toff=off.support[:-1].copy(),
        voff=off.traces[:-1].copy(),
        ncls=ncls,
        coff=np.cumsum([0, *ncls])[:-1].astype(np.int64),
        lam=np.array([b.lam for b in blocks], dtype=float),
        group=horde.block_group.astype(np.int64),
        owes=np.array([b.kernel.owes for b in blocks], dtype=np.bool_),
        alpha=per_slot("alpha"),
        alpha_w=per_slot("alpha_w"),
        beta=per_slot("beta"),
        temperature=per_slot("temperature"),
        epsilon=per_slot("epsilon"),
        reset=np.array([horde.demons[i].reset for i in horde.slot_demon], dtype=np.bool_).reshape(-1),
        slot_class=horde.slot_class.astype(np.int64),
        class_lo=np.concatenate(starts).astype(np.int64) if blocks else np.zeros(0, np.int64),
        class_hi=np.concatenate(ends).astype(np.int64) if blocks else np.zeros(0, np.int64),
        cut=float(horde.cut),
    )


def _groups(horde: Horde) -> Groups:
    groups = horde.groups

    def column(values: list[int]) -> np.ndarray:
        return np.array(values, dtype=np.int64)

    slot_lo = [int(horde.block_lo[g.blocks.start]) if len(g.blocks) else 0 for g in groups]
    return Groups(
        stage=column([g.stage for g in groups]),
        n_s=column([g.coder.n for g in groups]),
        k=column([g.coder.k for g in groups]),
        cond=column([int(horde.demon_slot[g.condition]) if g.condition >= 0 else -1 for g in groups]),
        block_lo=column([g.blocks.start for g in groups]),
        block_hi=column([g.blocks.stop for g in groups]),
        class_lo=column([g.classes.start for g in groups]),
        class_hi=column([g.classes.stop for g in groups]),
        slot_lo=column(slot_lo),
        slot_hi=column([lo + len(g.demons) for lo, g in zip(slot_lo, groups, strict=True)]),
    )


def _programs(horde: Horde) -> Programs:
    """The stages' question programs in one node table; prediction nodes read slots."""
    kinds: list[int] = []
    args: list[float] = []
    starts: list[int] = [0]
    children: list[int] = []
    stage_lo, stage_hi = [], []
    out = np.zeros((3, horde.num_demons), np.int64)  # per demon: nodes of cumulant, outcome, continuation
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
    discount = np.array([d.discount for d in horde.demons], dtype=float)
    return Programs(
        stage_lo=np.array(stage_lo, dtype=np.int64),
        stage_hi=np.array(stage_hi, dtype=np.int64),
        node_kind=np.array(kinds, dtype=np.int64),
        node_arg=np.array(args, dtype=float),
        node_start=np.array(starts, dtype=np.int64),
        node_children=np.array(children, dtype=np.int64),
        out_r=slot_out[0].copy(),
        out_z=slot_out[1].copy(),
        class_gnode=out[2, horde.class_demon].copy(),
        class_discount=discount[horde.class_demon],
        class_kind=horde.class_kind.copy(),
        class_of=np.where(horde.class_of >= 0, horde.demon_slot[np.maximum(horde.class_of, 0)], -1).astype(np.int64),
    )


def _world(world: World) -> GridWorld:
    spec = world.spec
    start = np.zeros(4)
    start[: len(spec.start)] = spec.start
    max_colors = max((len(v) for v in world.color_values), default=1)
    color_values = np.zeros((world.num_indicators, max_colors))
    color_cdf = np.ones((world.num_indicators, max_colors))
    color_count = np.zeros(world.num_indicators, dtype=np.int64)
    for i, (values, probs) in enumerate(zip(world.color_values, world.color_probs, strict=True)):
        cdf = np.cumsum(probs)
        color_values[i, : len(values)] = values
        color_cdf[i, : len(values)] = cdf / cdf[-1]
        color_count[i] = len(values)
    return GridWorld(
        width=float(spec.width),
        height=float(spec.height),
        step=float(spec.step),
        slip=float(spec.slip),
        noise=float(spec.noise),
        transient=float(spec.transient_reward),
        max_steps=float(spec.max_steps),
        start_rect=len(spec.start) == 4,
        start=start,
        rects=world.rects.copy(),
        is_obstacle=world.is_obstacle.astype(np.bool_),
        is_terminal=world.is_terminal.astype(np.bool_),
        term_reward=world.terminal_reward.copy(),
        term_ind=world.terminal_indicator.astype(np.int64),
        term_table=world.terminal_table.copy(),
        ind_region=np.array(world.indicator_regions, dtype=np.int64).reshape(-1),
        color_values=color_values,
        color_cdf=color_cdf,
        color_count=color_count,
    )


def _demons(horde: Horde, lay: Layout) -> Demons:
    d, na = horde.num_demons, horde.num_actions
    return Demons(
        alpha=lay.alpha.copy(),
        alpha_w=lay.alpha_w.copy(),
        r=np.zeros(d),
        z=np.zeros(d),
        pi=np.full((d, na), 1.0 / na),
        q=np.zeros((d, na)),
        pred=np.zeros(d),
        gamma=np.zeros(d),
        delta=np.zeros(d),
        cumulant=np.zeros(d),
        diverged=np.zeros(d, dtype=np.bool_),
    )


def _classes(horde: Horde) -> Classes:
    c, na = horde.num_classes, horde.num_actions
    return Classes(
        gamma=np.zeros(c),
        gamma_tp1=np.zeros(c),
        rho=np.ones(c),
        pi=np.full((c, na), 1.0 / na),
        pi_given=np.full((c, na), 1.0 / na),
        fixed=horde.class_fixed.copy(),
    )


def _scratch(horde: Horde, lay: Layout, nodes: int) -> Scratch:
    na = horde.num_actions
    sizes = (lay.block_hi - lay.block_lo).tolist()
    dmax = max([1, *sizes, *lay.ncls.tolist()])
    kmax = max((g.coder.k for g in horde.groups), default=1)
    most_rows = int(max([1, *horde.block_rows.tolist()]))
    work = np.zeros((8, dmax))
    return Scratch(
        node_values=np.zeros(max(1, nodes)),
        rows=np.zeros(most_rows + kmax, np.int64),
        rows_e=np.zeros(most_rows + kmax),
        rows_f=np.zeros(most_rows + kmax),
        rows_left=np.zeros(most_rows + kmax, np.int8),
        values=np.zeros((na, dmax)),
        pi_next=np.zeros((na, dmax)),
        work=work,
        scales=np.ones((3, dmax)),
        decay=np.zeros(dmax),
        add=np.zeros(dmax),
        mark=np.zeros(most_rows),
        counts=np.zeros(2, np.int64),
        ex=np.zeros((na, dmax)),
        ev=np.zeros((EV_ROWS, dmax), horde.dtype),  # trace values, what is owed: of the weights' dtype
        sums=work[1:7] if horde.dtype == np.float64 else np.zeros((6, dmax), horde.dtype),
    )


def _online(horde: Horde, lay: Layout, off: Offsets) -> Online:
    """The state of the learners beyond the gradient family, fresh: per-weight step sizes at alpha, scales 1."""
    blocks = horde.blocks
    cls_alpha = np.zeros(horde.num_classes)
    cls_beta = np.zeros(horde.num_classes)
    cls_alpha[horde.slot_class] = lay.alpha  # the demons of a true online class share alpha (and alpha_w)
    cls_beta[horde.slot_class] = lay.alpha_w
    step_a = (
        np.concatenate([np.tile(b.alpha, int(r)) for b, r in zip(blocks, horde.block_rows, strict=True)])
        if blocks
        else np.zeros(0)
    ).astype(horde.dtype)
    return Online(
        v_old=np.zeros(horde.num_demons),
        cls_alpha=cls_alpha,
        cls_beta=cls_beta,
        cls_f=np.zeros(horde.num_classes),
        cls_rho_prev=np.zeros(horde.num_classes),
        trace2=np.zeros(2 * int(off.traces[-1]), horde.dtype),
        support2=np.zeros(int(off.support[-1]), np.int64),
        nnz2=np.zeros(len(blocks), np.int64),
        w_read=np.zeros((3, horde.num_demons)),
        w_read_ok=np.zeros(len(blocks), np.int64),
        step_a=step_a,
        step_v=np.zeros(int(off.weights[-1]), horde.dtype),
        scale=np.ones(horde.num_demons),
        step_max=np.full(horde.num_demons, np.inf),  # (the engine counts it: `Engine.count_step_max`)
        meta=np.concatenate([np.asarray(b.meta, dtype=float) for b in blocks]) if blocks else np.zeros(0),
        tau=float(horde.plan.autostep_tau),
        bounds=np.zeros(int(max([1, *lay.ncls.tolist()])) + 1, np.int64),
    )
