"""Monte-Carlo rollouts of one demon's question, compiled: the frozen Horde follows the demon's target policy.

`evaluate.monte_carlo` packs the Horde and its world as the learning loop does (`fast.FastLoop`), copies the
weights in and calls `rollouts` once: every rollout runs here, one after the other, with the kernels of the
learning loop (`fast.py`: features, question programs; `scale_fast.py`: values and policies), and nothing
learns. Per step of a rollout: the demon's target policy picks an action, the world moves (slip, noise,
walls, terminals, as `fast._run` moves it), the groups that the demon reads (its own, those whose
predictions, policies or conditions it reads) are read at the new state, and the demon's stage program
gives r, z and the continuation there. The return is accumulated in expectation over the continuation:
G = sum_t (prod_{j<=t} gamma_j) (r_{t+1} + (1 - gamma_{t+1}) z_{t+1}).

Why compiled: the batched numpy rollouts cost about 1 us of Python and numpy per rollout step (a fifth of a
protocol trial of Experiment 1); here a step costs what the world and the demon's groups cost.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from horde.core.fast import (
    G_BHI,
    G_BLO,
    G_CHI,
    G_CLO,
    G_COND,
    G_K,
    G_NS,
    G_STAGE,
    W_TRANSIENT,
    Buffers,
    Net,
    _blocked,
    _displacement,
    _draw,
    _evaluate,
    _features,
    _given_policies,
    _given_to_slots,
    _inside,
    _sort,
    _start_sensors,
    _terminal_reward,
    _world_reset,
)
from horde.core.scale_fast import NO_NRT, _observe_block, _read_values


@njit(**NO_NRT)
def _read_groups(net, buf, wanted, x, y, sensors):
    """Values, policies and predictions of the wanted groups at (x, y) with these sensors, stage by stage."""
    gi, bi = net.gi, net.bi
    for g in range(gi.shape[0]):
        if not wanted[g]:
            continue
        k = gi[g, G_K]
        cond = buf.pred[gi[g, G_COND]] if gi[g, G_COND] >= 0 else 0.0
        _features(gi, net.thresholds, net.tiled_col, net.tiled_low, net.tiled_high, buf.tiled_values, net.table, g,
                  x, y, sensors, cond, net.wp, buf.feat[g])  # fmt: skip
        _sort(buf.feat[g], k)
        _given_policies(gi, net.class_kind, net.class_of, net.class_fixed, buf.pi, buf.pi_given, g)
        blo, bhi = gi[g, G_BLO], gi[g, G_BHI]
        bi_g = bi[blo:bhi]
        for b in range(bhi - blo):
            _read_values(bi_g, b, gi[g, G_NS], buf.theta, buf.feat[g, :k], buf.values)
            _observe_block(bi_g, b, net.dcls, net.temperature, net.epsilon, buf.pi_given, buf.values, buf.q, buf.pi,
                           buf.pred, buf.scratch[0], buf.scratch[1])  # fmt: skip
        _given_to_slots(gi, bi, net.dcls, buf.pi, buf.pi_given, g)
        for c in range(gi[g, G_CLO], gi[g, G_CHI]):
            for a in range(buf.class_pi.shape[1]):
                buf.class_pi[c, a] = buf.pi_given[c, a]


@njit(**NO_NRT, nogil=True)
def rollouts(net, buf, rng, slot, group, wanted, start_x, start_y, cap, floor, totals, cdf, inside):
    """Run len(totals) rollouts of slot `slot`'s question (in group `group`) from (start_x, start_y).

    Each draws the indicators' colours as an episode start does, then follows the slot's target policy
    until its continuation weight falls to `floor` or below, or for `cap` steps. Writes each rollout's
    return into `totals` and returns how many were still running at the cap.
    """
    gi, wp, rects = net.gi, net.wp, net.rects
    num_regions = rects.shape[0]
    num_indicators = net.ind_region.shape[0]
    stage = gi[group, G_STAGE]
    lo, hi = net.stage_lo[stage], net.stage_hi[stage]
    c = net.dcls[slot]
    gnode, discount = net.class_gnode[c], net.class_discount[c]
    rnode, znode = net.out_r[slot], net.out_z[slot]
    num_actions = buf.pi.shape[1]
    sensors = buf.sensors
    capped = 0
    for n in range(totals.shape[0]):
        _world_reset(rng, wp, rects, net.is_obstacle, net.is_terminal, net.color_cdf, net.color_count, buf.pos,
                     buf.wsteps, buf.colors)  # fmt: skip
        buf.pos[0] = start_x
        buf.pos[1] = start_y
        _start_sensors(net, buf)
        _read_groups(net, buf, wanted, start_x, start_y, buf.start_sensors)
        total = 0.0
        weight = 1.0
        for _ in range(cap):
            acc = 0.0
            for a in range(num_actions):
                acc += buf.pi[slot, a]
                cdf[a] = acc
            action = _draw(rng, cdf, num_actions)
            dx, dy = _displacement(rng, wp, action)
            nx = buf.pos[0] + dx
            ny = buf.pos[1] + dy
            bump = 0.0
            if _blocked(wp, rects, net.is_obstacle, nx, ny):
                nx = buf.pos[0]
                ny = buf.pos[1]
                bump = 1.0
            _inside(wp, rects, nx, ny, inside)
            terminated = False
            for r in range(num_regions):
                if inside[r] and net.is_terminal[r]:
                    terminated = True
            terminal = 0.0
            if terminated:
                terminal = _terminal_reward(net.is_terminal, inside, net.term_reward, net.term_ind, net.term_table,
                                            buf.colors)  # fmt: skip
            buf.wsteps[0] += 1
            buf.pos[0] = nx
            buf.pos[1] = ny
            sensors[0] = nx
            sensors[1] = ny
            sensors[2] = bump
            sensors[3] = float(buf.wsteps[0])
            sensors[4] = wp[W_TRANSIENT] + terminal
            for r in range(num_regions):
                sensors[5 + r] = 1.0 if inside[r] else 0.0
            for i in range(num_indicators):
                sensors[5 + num_regions + i] = net.color_values[i, buf.colors[i]] if inside[net.ind_region[i]] else 0.0
            sensors[5 + num_regions + num_indicators] = 1.0 if terminated else 0.0
            _read_groups(net, buf, wanted, nx, ny, sensors)
            _evaluate(lo, hi, net.node_kind, net.node_arg, net.node_start, net.node_children, sensors, buf.pred,
                      buf.node_values)  # fmt: skip
            gamma = 0.0 if terminated else min(max(buf.node_values[gnode], 0.0), 1.0) * discount
            total += weight * (buf.node_values[rnode] + (1.0 - gamma) * buf.node_values[znode])
            weight *= gamma
            if weight <= floor:
                break
        if weight > floor:
            capped += 1
        totals[n] = total
    return capped


def run_rollouts(
    net: Net,
    buf: Buffers,
    rng: np.random.Generator,
    slot: int,
    group: int,
    wanted: np.ndarray,
    start: tuple[float, float],
    count: int,
    cap: int,
    floor: float,
) -> tuple[np.ndarray, int]:
    """`rollouts` with its output allocated: ([count] returns, how many were capped)."""
    totals = np.zeros(count)
    cdf = np.zeros(buf.pi.shape[1])
    inside = np.zeros(net.rects.shape[0], dtype=np.bool_)
    capped = rollouts(net, buf, rng, slot, group, wanted, float(start[0]), float(start[1]), cap, floor, totals, cdf,
                      inside)  # fmt: skip
    return totals, int(capped)
