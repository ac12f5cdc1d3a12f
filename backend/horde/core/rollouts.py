"""Monte-Carlo rollouts of one demon's question, compiled: the frozen Horde follows the demon's target policy.

`evaluate.monte_carlo` packs the Horde and its world as the learning loop does (`engine.Engine`), copies the
weights in and calls `rollouts`: every rollout runs here, one after the other, with the engine's kernels
(`engine.grid`: the world; `features.code`; `questions.evaluate_nodes`; `engine.values`: values and
policies), and nothing learns. Per step of a rollout: the demon's target policy picks an action, the world
moves (slip, noise, walls, terminals, as the learning loop moves it), the groups that the demon reads (its
own, those whose predictions, policies or conditions it reads) are read at the new state, and the demon's
stage program gives r, z and the continuation there. The return is accumulated in expectation over the
continuation: G = sum_t (prod_{j<=t} gamma_j) (r_{t+1} + (1 - gamma_{t+1}) z_{t+1}).

Why compiled: the batched numpy rollouts cost about 1 us of Python and numpy per rollout step (a fifth of a
protocol trial of Experiment 1); here a step costs what the world and the demon's groups cost.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from horde.core.engine import grid
from horde.core.engine.layout import NO_NRT, Tables
from horde.core.engine.step import given_policies, given_to_slots
from horde.core.engine.values import read_and_observe
from horde.core.features import code
from horde.core.questions import evaluate_nodes


class Question(NamedTuple):
    """The demon whose question the rollouts answer, and what they read."""

    slot: int
    group: int
    wanted: np.ndarray  # [G] bool: the groups the demon reads
    start_x: float
    start_y: float
    cap: int  # steps of a rollout at most
    floor: float  # a rollout whose continuation weight falls to this has finished


@njit(**NO_NRT)
def _read_groups(t, wanted, x, y, sensors):
    """Values, policies and predictions of the wanted groups at (x, y) with these sensors, stage by stage."""
    grp, coded, cls = t.grp, t.coded, t.cls
    for g in range(grp.stage.shape[0]):
        if not wanted[g]:
            continue
        cond = t.dem.pred[grp.cond[g]] if grp.cond[g] >= 0 else 0.0
        m = code(t.codes, g, x, y, sensors, cond, coded.inputs, coded.taken, coded.features[g], coded.values[g])
        coded.counts[g] = m
        given_policies(g, grp, t.progs, t.dem, cls)
        for b in range(grp.block_lo[g], grp.block_hi[g]):
            read_and_observe(b, t.lay, t.wts, t.dem, cls, t.scr, coded.features[g, :m], coded.values[g, :m], grp.n_s[g])
        given_to_slots(g, grp, t.lay, t.dem, cls)
        for c in range(grp.class_lo[g], grp.class_hi[g]):
            for a in range(cls.pi.shape[1]):
                cls.pi[c, a] = cls.pi_given[c, a]


@njit(cache=True, nogil=True)
def rollouts(t, rng, question, totals):
    """Run len(totals) rollouts of the question (see `Question`) from its start.

    Each draws the indicators' colours as an episode start does, then follows the slot's target policy
    until its continuation weight falls to the floor or below, or for `cap` steps. Writes each rollout's
    return into `totals` and returns how many were still running at the cap.
    """
    world, agent, progs = t.world, t.agent, t.progs
    slot = question.slot
    stage = t.grp.stage[question.group]
    c = t.lay.slot_class[slot]
    gnode, discount = progs.class_gnode[c], progs.class_discount[c]
    rnode, znode = progs.out_r[slot], progs.out_z[slot]
    num_actions = t.dem.pi.shape[1]
    values = t.scr.node_values
    capped = 0
    for n in range(totals.shape[0]):
        grid.reset(rng, world, agent)
        agent.pos[0] = question.start_x
        agent.pos[1] = question.start_y
        grid.start_sensors(world, agent)
        _read_groups(t, question.wanted, question.start_x, question.start_y, agent.start_sensors)
        total = 0.0
        weight = 1.0
        for _ in range(question.cap):
            acc = 0.0
            for a in range(num_actions):
                acc += t.dem.pi[slot, a]
                agent.cdf[a] = acc
            action = grid.draw(rng, agent.cdf, num_actions)
            _, terminated, _ = grid.move(rng, world, agent, action)
            _read_groups(t, question.wanted, agent.pos[0], agent.pos[1], agent.sensors)
            evaluate_nodes(progs, stage, agent.sensors, t.dem.pred, values)
            gamma = 0.0 if terminated else min(max(values[gnode], 0.0), 1.0) * discount
            total += weight * (values[rnode] + (1.0 - gamma) * values[znode])
            weight *= gamma
            if weight <= question.floor:
                break
        if weight > question.floor:
            capped += 1
        totals[n] = total
    return capped


def run_rollouts(t: Tables, rng: np.random.Generator, question: Question, count: int) -> tuple[np.ndarray, int]:
    """`rollouts` with its output allocated: ([count] returns, how many were capped)."""
    totals = np.zeros(count)
    capped = rollouts(t, rng, question, totals)
    return totals, int(capped)
