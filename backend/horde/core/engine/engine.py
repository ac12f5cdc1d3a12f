"""`Engine`: a compiled Horde in the engine's tables, with its state in and out.

`pack.py` builds the tables; the compiled loop (`loop.run`) and step (`step.learn`, `step.observe`) change
them in place; this module reads them out as `horde.py`'s `HordeState` (and `AdaptiveState`, what the
learners beyond the gradient family keep) and loads them back, and runs the loop on the grid world or on
given rows. `horde.core.learner.Learner` (every source's one interface) and `Simulation` (the grid world)
stand on it.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from horde.core import metrics
from horde.core.engine import loop, step
from horde.core.engine.layout import FOREVER, NO_GIVEN, Behaviour, Given, Tables
from horde.core.engine.pack import offsets, pack
from horde.core.horde import Horde, HordeState
from horde.core.policies import KIND_CODES
from horde.core.world import World, WorldState
from horde.spec import BehaviourSpec


class AdaptiveState(NamedTuple):
    """What the learners beyond the gradient family keep that changes as they learn (in the engine's layout):
    the snapshot's `online` part."""

    v_old: np.ndarray  # [D] true online learners: theta_{t-1} . x_t
    cls_f: np.ndarray  # [C] emphatic TD's followon trace per class
    cls_rho_prev: np.ndarray  # [C] rho_{t-1} per class
    trace2: np.ndarray  # true online GTD's second and third traces
    step_a: np.ndarray  # per-weight step sizes of autostep / tidbd demons (before their scale)
    step_v: np.ndarray  # autostep's normaliser v per weight
    ascale: np.ndarray  # [D] the scale of each demon's step sizes (adaptive TD), of its w (tdrc)


class Engine:
    """One agent's compiled Horde (and its grid world, when it has one): the engine's tables and their state.

    Args:
        horde: the compiled demons.
        world: the grid world the loop moves the agent in; None for a world fed from outside (`learn_given`).
    """

    def __init__(self, horde: Horde, world: World | None = None) -> None:
        self.horde = horde
        self.world = world
        self.t: Tables = pack(horde, world)
        self._offsets = offsets(horde)
        self.count_step_max()

    # ------------------------------------------------------------------------------------------
    # Views of the flat buffers

    def _block(self, flat: np.ndarray, b: int, columns: int, at: np.ndarray) -> np.ndarray:
        rows = int(self.horde.block_rows[b])
        return flat[at[b] : at[b] + rows * columns].reshape(rows, columns)

    def weights(self, flat: np.ndarray, b: int) -> np.ndarray:
        """Block b's [rows, Db] view of a flat per-weight buffer (theta, w, h, u, step sizes)."""
        return self._block(flat, b, self.horde.blocks[b].size, self._offsets.weights)

    def traces(self, b: int) -> np.ndarray:
        """Block b's [rows, C_b] view of the traces."""
        return self._block(self.t.wts.trace, b, self.horde.blocks[b].num_classes, self._offsets.traces)

    def traces2(self, b: int) -> np.ndarray:
        """Block b's [2, rows, C_b] view of true online GTD's e_grad and e_w (zero for other learners)."""
        rows, ncls, at = int(self.horde.block_rows[b]), self.horde.blocks[b].num_classes, 2 * self._offsets.traces[b]
        return self.t.onl.trace2[at : at + 2 * rows * ncls].reshape(2, rows, ncls)

    def per_demon(self, slots: np.ndarray) -> np.ndarray:
        """A per-slot array in demon order (a copy)."""
        out = np.empty_like(slots)
        out[self.horde.slot_demon] = slots
        return out

    def active_features(self, g: int) -> np.ndarray:
        """Group g's active features at the state the agent stands in (their indices, a copy)."""
        return self.t.coded.features[g, : self.t.coded.counts[g]].copy()

    def nbytes(self) -> int:
        """Bytes of every array of the engine's tables."""
        return sum(a.nbytes for table in self.t for a in table if isinstance(a, np.ndarray))

    def prediction(self) -> np.ndarray:
        """[D] predictions in demon order (a copy)."""
        return self.per_demon(self.t.dem.pred)

    # ------------------------------------------------------------------------------------------
    # Stepping

    def set_learning(self, learning: np.ndarray | None) -> None:
        """Which demons learn ([D] bool, default all); diverged demons stay frozen."""
        live = ~self.t.dem.diverged
        if learning is not None:
            live &= np.asarray(learning, dtype=bool)[self.horde.slot_demon]
        self.t.dem.alpha[:] = np.where(live, self.t.lay.alpha, 0.0)
        self.t.dem.alpha_w[:] = np.where(live, self.t.lay.alpha_w, 0.0)

    def freeze(self, slots: np.ndarray) -> None:
        """Mark these slots diverged and freeze them as the compiled step does (`step.freeze_slot`): step
        sizes 0, weights 0, nothing owed."""
        t = self.t
        for slot in np.asarray(slots, dtype=np.int64):
            b = int(np.searchsorted(self.horde.block_lo, slot, side="right")) - 1
            step.freeze_slot(b, int(slot - self.horde.block_lo[b]), t.lay, t.wts, t.dem, t.onl)

    def _behaviour(self, behaviour: BehaviourSpec) -> Behaviour:
        demon = int(self.horde.demon_slot[self.horde.index[behaviour.demon]]) if behaviour.demon else -1
        na = self.horde.num_actions
        probs = np.asarray(behaviour.probabilities if behaviour.probabilities else [1.0 / na] * na, dtype=float)
        return Behaviour(KIND_CODES[behaviour.kind], demon, float(behaviour.temperature), float(behaviour.epsilon),
                         probs)  # fmt: skip

    def reset_world(self, rng: np.random.Generator) -> None:
        """A new episode on the grid world: it draws its start and colours, the Horde observes the first state."""
        loop.start(self.t, rng)

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
        """Step on the grid world until `max_steps` steps or `max_episodes` ended episodes; returns the result
        fields (`loop.R_*`). Blocks of at least `PARALLEL_MIN` demons learn on `threads` threads."""
        self.set_learning(learning)
        self.t.agent.result[:] = 0.0
        loop.run(self.t, rng, max_steps, max_episodes, self._behaviour(behaviour or self.horde.behaviour),
                 with_metrics, threads, NO_GIVEN)  # fmt: skip
        return self.t.agent.result

    def learn_given(self, given: Given, with_metrics: bool = True, threads: int = 1) -> None:
        """Learn from the transitions of `given`, in order (a world fed from outside)."""
        beh = self._behaviour(BehaviourSpec())
        loop.run(self.t, np.random.default_rng(0), len(given.actions), FOREVER, beh, with_metrics, threads, given)

    def observe(self, sensors: np.ndarray | None = None, rules: np.ndarray | None = None) -> None:
        """Traces to zero, and the Horde observes the state the agent stands in: at these sensors (a world fed
        from outside; `rules`: its sign policies), else where the grid world's agent stands (after a load with
        new demons)."""
        agent = self.t.agent
        if sensors is not None:
            agent.sensors[:] = sensors
        agent.start_sensors[:] = agent.sensors
        if rules is not None:
            step.apply_rules(rules, agent.sensors, self.t.cls.fixed)
        position = (agent.pos[0], agent.pos[1]) if self.world is not None else (0.0, 0.0)
        step.observe(self.t, position[0], position[1], agent.start_sensors)

    # ------------------------------------------------------------------------------------------
    # Reading out

    def rupee(self) -> np.ndarray:
        """[D] RUPEE of every demon, in O(D) (the dot products are kept up to date by the loop)."""
        met = self.t.met
        scale = met.scale[self.horde.block_group] if len(self.horde.blocks) else np.zeros(0)
        sizes = [b.size for b in self.horde.blocks]
        per_slot = np.repeat(scale, sizes) * met.hu if sizes else np.zeros(0)
        return self.per_demon(np.sqrt(np.abs(per_slot)))

    def ude(self) -> np.ndarray:
        return metrics.ude_of(self.per_demon(self.t.met.stats))

    def thetas(self) -> list[np.ndarray]:
        return [self.weights(self.t.wts.theta, b).copy() for b in range(len(self.horde.blocks))]

    def step_sizes(self, name: str) -> np.ndarray:
        """[n] one demon's step size of every weight now: per-weight (autostep, tidbd) or alpha (constant)."""
        b, col = self.horde.locate(name)
        slot = int(self.horde.demon_slot[self.horde.index[name]])
        if self.horde.blocks[b].step_size == "constant":
            return np.full(int(self.horde.block_rows[b]), self.t.lay.alpha[slot])
        return self.weights(self.t.onl.step_a, b)[:, col] * self.t.onl.scale[slot]

    def count_step_max(self) -> None:
        """Each Autostep demon's largest stored step size, counted again over all its weights (`Online.step_max`;
        the kernels keep it as their meta steps, folds, freezes and resets move step sizes). Call it after
        writing step sizes from outside the kernels: Autostep's one-walk step trusts it as an upper bound."""
        onl = self.t.onl
        for b, block in enumerate(self.horde.blocks):
            if block.step_size == "autostep":
                lo = int(self.horde.block_lo[b])
                sizes = self.weights(onl.step_a, b)
                onl.step_max[lo : lo + block.size] = sizes.max(axis=0) if sizes.shape[0] else 0.0

    def effective_step_sizes(self) -> np.ndarray:
        """[D] the step size each demon takes at the agent's state, in the units of `alpha` (before the division
        by the active count): alpha for a constant step size; the sum of the per-weight step sizes over the
        active features for autostep and tidbd."""
        out = np.zeros(self.horde.num_demons)
        coded = self.t.coded
        for g, group in enumerate(self.horde.groups):
            active = coded.features[g, : coded.counts[g]]
            for b in group.blocks:
                block = self.horde.blocks[b]
                lo = int(self.horde.block_lo[b])
                slots = np.arange(lo, lo + block.size)
                if block.step_size == "constant":
                    values = self.t.lay.alpha[slots] * group.coder.k
                else:
                    values = self.weights(self.t.onl.step_a, b)[active].sum(axis=0) * self.t.onl.scale[slots]
                out[self.horde.slot_demon[slots]] = values
        return out

    def _true_w(self, b: int) -> np.ndarray:
        """Block b's secondary weights as the equations read them (a learner may keep them scaled per demon)."""
        w = self.weights(self.t.wts.w, b).copy()
        if self.horde.blocks[b].kernel.scaled_w:
            lo = int(self.horde.block_lo[b])
            w = (w * self.t.onl.scale[lo : lo + self.horde.blocks[b].size]).astype(self.horde.dtype)
        return w

    def horde_state(self, weights_only: bool = False) -> HordeState:
        """A copy of the state in `horde.py`'s form (weights_only: w, e, h and delta_e left empty)."""
        horde, t = self.horde, self.t
        blocks = range(len(horde.blocks))
        rest = range(0 if weights_only else len(horde.blocks))
        q = self.per_demon(t.dem.q)
        q[~horde.is_action_value] = np.nan
        coded = t.coded
        return HordeState(
            theta=tuple(self.weights(t.wts.theta, b).copy() for b in blocks),
            w=tuple(self._true_w(b) for b in rest),
            e=tuple(self.traces(b).copy() for b in rest),
            h=tuple(self.weights(t.met.h, b).copy() for b in rest),
            delta_e=tuple(self.weights(t.met.u, b).copy() for b in rest),
            delta_e_scale=t.met.scale.copy(),
            rupee_dot=self.per_demon(t.met.hu),
            tau=t.met.tau.copy(),
            delta_stats=self.per_demon(t.met.stats),
            features=tuple(coded.features[g, : group.coder.k].copy() for g, group in enumerate(horde.groups)),
            class_gamma=t.cls.gamma.copy(),
            class_pi=t.cls.pi.copy(),
            pi=self.per_demon(t.dem.pi),
            q=q,
            prediction=self.per_demon(t.dem.pred),
            gamma=self.per_demon(t.dem.gamma),
            delta=self.per_demon(t.dem.delta),
            cumulant=self.per_demon(t.dem.cumulant),
            diverged=self.per_demon(t.dem.diverged),
            feature_values=tuple(
                np.where(np.arange(group.coder.k) < coded.counts[g], coded.values[g, : group.coder.k], 0.0)
                for g, group in enumerate(horde.groups)
            ),
        )

    def world_state(self) -> WorldState:
        agent = self.t.agent
        return WorldState(x=agent.pos[:1].copy(), y=agent.pos[1:].copy(), steps=agent.steps.copy(),
                          colors=agent.colors[None, :].copy())  # fmt: skip

    def set_world_state(self, world_state: WorldState) -> None:
        """Put the grid world's agent (the first of a world state) where the state says."""
        agent = self.t.agent
        agent.pos[:] = (world_state.x[0], world_state.y[0])
        agent.steps[0] = world_state.steps[0]
        agent.colors[:] = world_state.colors[0]

    def load(self, state: HordeState, world_state: WorldState | None = None) -> None:
        """Copy a `HordeState` (and the first agent of a grid world's state) into the tables."""
        horde, t = self.horde, self.t
        slot = horde.slot_demon
        for b in range(len(horde.blocks)):
            self.weights(t.wts.theta, b)[:] = state.theta[b]
            self.weights(t.wts.w, b)[:] = state.w[b]
            if horde.blocks[b].kernel.scaled_w:  # w comes as the equations read it: unscaled
                lo = int(horde.block_lo[b])
                t.onl.scale[lo : lo + horde.blocks[b].size] = 1.0
            self.weights(t.met.h, b)[:] = state.h[b]
            self.weights(t.met.u, b)[:] = state.delta_e[b]
            e = self.traces(b)
            e[:] = state.e[b]
            rows = np.flatnonzero((e != 0.0).any(axis=1))
            at = int(self._offsets.support[b])
            t.wts.support[at : at + len(rows)] = rows
            t.wts.nnz[b] = len(rows)
        t.met.scale[:] = state.delta_e_scale
        t.met.hu[:] = state.rupee_dot[slot]
        t.met.tau[:] = state.tau
        t.met.stats[:] = state.delta_stats[slot]
        for g in range(len(horde.groups)):  # a feature of value 0 is one not active (the padding)
            keep = np.flatnonzero(state.feature_values[g] != 0.0)
            t.coded.features[g, : len(keep)] = state.features[g][keep]
            t.coded.values[g, : len(keep)] = state.feature_values[g][keep]
            t.coded.counts[g] = len(keep)
        t.cls.gamma[:] = state.class_gamma
        t.cls.pi[:] = state.class_pi
        t.dem.pi[:] = state.pi[slot]
        t.dem.q[:] = np.nan_to_num(state.q[slot], nan=0.0)
        t.dem.q[~horde.is_action_value[slot], 0] = state.prediction[slot][~horde.is_action_value[slot]]
        t.dem.pred[:] = state.prediction[slot]
        t.dem.gamma[:] = state.gamma[slot]
        t.dem.delta[:] = state.delta[slot]
        t.dem.cumulant[:] = state.cumulant[slot]
        t.dem.diverged[:] = state.diverged[slot]
        t.wts.owed[:] = 0.0  # a state's theta owes nothing (the loop pays all before it returns)
        t.onl.w_read_ok[:] = 0  # its w and features are new: true online GTD's and TIDBD's next step read w afresh
        if world_state is not None:
            self.set_world_state(world_state)

    def adaptive_state(self) -> AdaptiveState:
        """Copies of what the learners beyond the gradient family keep (`AdaptiveState`)."""
        onl = self.t.onl
        return AdaptiveState(onl.v_old.copy(), onl.cls_f.copy(), onl.cls_rho_prev.copy(), onl.trace2.copy(),
                             onl.step_a.copy(), onl.step_v.copy(), onl.scale.copy())  # fmt: skip

    def load_adaptive_state(self, state: AdaptiveState) -> None:
        """Copy an `adaptive_state()` of an engine of the same spec back, after `load`: a w kept scaled (tdrc, the
        original GTD) keeps the scale 1 that `load` gave it, since `load` took w as the equations read it (the
        saved scale multiplied the restored w a second time: a snapshot's TDRC demon came back with h times s)."""
        onl = self.t.onl
        for into, array in zip((onl.v_old, onl.cls_f, onl.cls_rho_prev, onl.trace2, onl.step_a, onl.step_v,
                                onl.scale), state, strict=True):  # fmt: skip
            into[...] = array
        self.count_step_max()
        onl.w_read_ok[:] = 0  # true online GTD's traces are new: its next step reads w afresh
        for b, block in enumerate(self.horde.blocks):  # true online GTD's second and third traces' support
            rows = np.flatnonzero((self.traces2(b) != 0.0).any(axis=(0, 2)))
            at = int(self._offsets.support[b])
            onl.support2[at : at + len(rows)] = rows
            onl.nnz2[b] = len(rows)
            if block.kernel.scaled_w:
                lo = int(self.horde.block_lo[b])
                onl.scale[lo : lo + block.size] = 1.0
