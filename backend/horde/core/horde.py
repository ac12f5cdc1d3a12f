"""The Horde compiled for the one engine: stages, groups, blocks and trace classes.

A run's demons compile, once, into four nested levels:

* **stage**: demons whose inputs (predictions read as cumulants, policies of other demons, conditioned
  features) come from earlier stages, so that a prediction read by another demon is the one for
  s_{t+1} after its owner's update at this step;
* **group**: demons of one stage that share a feature spec and the kind of values (state-action
  features for GQ). A group's active features are computed once per step;
* **block**: demons of a group with the same learner (and step-size mode), lambda and kind of target
  policy (given to the block, or each demon's own greedy / softmax / epsilon-greedy policy); weights are
  feature-major `[n, Db]` (DESIGN section 6, `engine/blocks.py`);
* **trace class**: demons of a given-policy block with the same target policy, continuation and
  discount have the same eligibility trace and share one column `[n, 1]` of it.

The spec is resolved once into a plan (`plan.py`); the Horde compiles from the plan alone. Blocks and classes
are numbered across groups; the engine's "slots" are the demons in block order. `HordeState` holds
everything that changes, as arrays. The learning itself is compiled (`engine/`, with the kernels of
`learners/`); each learner module writes its equations as readable numpy and `reference.py` as the plain
oracle. This module also evaluates a frozen Horde at a batch of positions (`forward`), for value maps and
Monte-Carlo truth.

Why one module of about 540 lines: compiling a plan into stages, groups, blocks and trace classes,
the state they make and reading it out (forward, behaviour) share the layout's private lists; split, each
part would have to reach into the others'.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from horde.core import metrics
from horde.core.engine.blocks import POLICY_CODES, TRACE_CUT, Block, BlockPolicy, trace_classes
from horde.core.engine.layout import MAX_MAGNITUDE
from horde.core.features import StateCoder
from horde.core.plan import DemonPlan, Plan, resolve
from horde.core.policies import FIXED, KIND_CODES, OF, OWN_VALUE, UNIFORM, value_policy
from horde.core.questions import Program
from horde.core.world import World, WorldState
from horde.spec import BehaviourSpec, DemonSpec, RunSpec

__all__ = ["MAX_MAGNITUDE", "OF", "UNIFORM", "Forward", "Group", "Horde", "HordeState", "Stage"]
POSITION_KINDS = ("stripes", "tiles", "grid", "constant")  # the kinds that code a position alone


@dataclass(frozen=True)
class Group:
    """Demons of one stage over one feature set."""

    stage: int
    coder: StateCoder
    action_values: bool
    condition: int  # global index of the condition demon, or -1
    demons: np.ndarray  # [Dg] global demon indices, in slot order (block by block, class by class)
    blocks: range  # global block numbers
    classes: range  # global trace classes


@dataclass(frozen=True)
class Stage:
    groups: tuple[Group, ...]
    demons: np.ndarray  # [Ds] global indices, in the program's column order
    program: Program  # 3 * Ds outputs: cumulants, outcomes, continuations
    discount: np.ndarray  # [Ds]


class HordeState(NamedTuple):
    """Everything that changes while a Horde learns (one agent). Blocks and classes are global."""

    theta: tuple[np.ndarray, ...]  # per block [n_b, Db] primary weights, feature-major
    w: tuple[np.ndarray, ...]  # per block [n_b, Db] secondary weights (tdrc: h)
    e: tuple[np.ndarray, ...]  # per block [n_b, C_b] one trace per class
    h: tuple[np.ndarray, ...]  # per block [n_b, Db] RUPEE's weights
    delta_e: tuple[np.ndarray, ...]  # per block [n_b, Db] RUPEE's average of delta e, divided by delta_e_scale
    delta_e_scale: np.ndarray  # [G] per group: the average of delta e decays lazily, by this one number
    rupee_dot: np.ndarray  # [D] h . delta_e of each demon (kept up to date; RUPEE = sqrt(|scale rupee_dot|))
    tau: np.ndarray  # [G, 2] the unbiased-start weights of RUPEE and UDE, per group
    delta_stats: np.ndarray  # [D, 3] averages of delta, delta^2 and |delta|
    features: tuple[np.ndarray, ...]  # per group [k] active state features at s_t (sorted, then padding)
    class_gamma: np.ndarray  # [C] continuation of each trace class at s_t
    class_pi: np.ndarray  # [C, A] target policy of each class at s_t (own-value classes: unused)
    pi: np.ndarray  # [D, A] target policy at s_t
    q: np.ndarray  # [D, A] action values at s_t (nan for state-value demons)
    prediction: np.ndarray  # [D] prediction at s_t
    gamma: np.ndarray  # [D] continuation at s_t
    delta: np.ndarray  # [D] last TD error
    cumulant: np.ndarray  # [D] last cumulant
    diverged: np.ndarray  # [D] bool: weights went non-finite, frozen since
    feature_values: tuple[np.ndarray, ...]  # per group [k] the values of `features` (0 on the padding)


class Forward(NamedTuple):
    """What the frozen Horde says about a batch of positions."""

    prediction: np.ndarray  # [B, D]
    pi: np.ndarray  # [B, D, A]
    q: np.ndarray  # [B, D, A] (nan for state-value demons)
    features: tuple[np.ndarray, ...]  # per group [B, k]


def _policy_key(demon: DemonPlan) -> tuple[object, ...]:
    policy = demon.policy
    if policy.kind == "fixed" and policy.probabilities is not None:
        return ("fixed", tuple(float(p) for p in policy.probabilities))
    if policy.kind == "of":
        return ("of", policy.demon)
    if policy.kind == "sign":
        return ("sign", policy.sensor, tuple(policy.actions or ()), float(policy.epsilon))
    return ("uniform",)


def _trace_key(demon: DemonPlan) -> tuple[object, ...]:
    """What a demon's trace depends on: its target policy, continuation and discount; a dutch trace (true
    online learners) holds alpha (and true online GTD's w trace alpha_w), so only demons of one step size
    share one."""
    dutch = (demon.alpha, demon.alpha_w if demon.kernel.vectors > 1 else 0.0) if demon.kernel.dutch else ()
    return (_policy_key(demon), repr(demon.continuation), demon.discount, *dutch)


class Horde:
    """A compiled set of demons over one world.

    Args:
        spec: the run spec (its world, default features, learning defaults, behaviour and demons); resolved
            once into a plan (`plan.py`), which the Horde compiles from.
        cut: the trace cut (DESIGN section 6; 0 keeps every non-zero trace entry).
    """

    def __init__(self, spec: RunSpec, cut: float = TRACE_CUT) -> None:
        self.spec = spec
        self.cut = cut
        self.plan: Plan = resolve(spec)
        plan = self.plan
        self.dtype = np.dtype(plan.dtype)  # of the weights, traces and per-weight vectors (`[learning] dtype`)
        self.demon_specs: list[DemonSpec] = list(spec.demons)
        self.demons: tuple[DemonPlan, ...] = plan.demons
        self.names = [d.name for d in plan.demons]
        self.index = {name: i for i, name in enumerate(self.names)}
        self.num_demons = len(self.names)
        self.stage_of = np.array([d.stage for d in plan.demons], dtype=np.int64)
        self.is_action_value = np.array([d.action_values for d in plan.demons], dtype=bool)
        self.num_actions = plan.num_actions  # A: four in the grid world, the space's size elsewhere
        # Filled by _compile: per trace class, what its given target policy is.
        self._class_kind: list[int] = []
        self._class_fixed: list[np.ndarray] = []
        self._class_of: list[int] = []
        self._class_demon: list[int] = []
        self._blocks: list[Block] = []
        self.stages = self._compile(plan)
        self.groups: tuple[Group, ...] = tuple(g for stage in self.stages for g in stage.groups)
        self.blocks: tuple[Block, ...] = tuple(self._blocks)
        self.class_kind = np.array(self._class_kind, dtype=np.int64)  # [C] UNIFORM / FIXED / OF, or own kind
        self.class_fixed = np.array(self._class_fixed, dtype=float).reshape(-1, self.num_actions)  # [C, A]
        self.class_of = np.array(self._class_of, dtype=np.int64)  # [C] demon followed, or -1
        self.class_demon = np.array(self._class_demon, dtype=np.int64)  # [C] one demon of the class
        self.num_classes = len(self.class_kind)
        self.slot_demon = np.concatenate([g.demons for g in self.groups]) if self.groups else np.zeros(0, np.int64)
        self.demon_slot = np.empty(self.num_demons, dtype=np.int64)
        self.demon_slot[self.slot_demon] = np.arange(self.num_demons)
        self.block_group = np.array(
            [i for i, g in enumerate(self.groups) for _ in g.blocks], dtype=np.int64
        )  # [B] group of each block
        self.block_rows = np.array(
            [g.coder.n * (self.num_actions if g.action_values else 1) for g in self.groups for _ in g.blocks],
            dtype=np.int64,
        )  # [B] weight rows of each block
        sizes = [b.size for b in self.blocks]
        self.block_lo = np.cumsum([0, *sizes])[:-1].astype(np.int64)  # [B] first slot of each block
        class_lo = np.cumsum([0, *(b.num_classes for b in self.blocks)])[:-1].astype(np.int64)
        self.slot_class = (
            np.concatenate([lo + b.classes for lo, b in zip(class_lo, self.blocks, strict=True)]).astype(np.int64)
            if self.blocks
            else np.zeros(0, np.int64)
        )  # [D] global class of each slot
        self.behaviour = plan.behaviour
        self.behaviour_demon = self.index[plan.behaviour.demon] if plan.behaviour.demon else -1

    # ------------------------------------------------------------------------------------------
    # Compilation

    def _compile(self, plan: Plan) -> tuple[Stage, ...]:
        sensor_index = {name: i for i, name in enumerate(plan.sensors)}
        # One pass over the demons (a chain of 1,000 demons has 1,000 stages: a pass per stage held the
        # GIL long enough to delay the server's other requests), and one coder per feature set.
        coders: dict[str, StateCoder] = {}
        by_stage: list[dict[tuple[str, bool], list[int]]] = [{} for _ in range(max(self.stage_of, default=-1) + 1)]
        for i, demon in enumerate(plan.demons):
            by_stage[demon.stage].setdefault((demon.feature_key, demon.action_values), []).append(i)
            if demon.feature_key not in coders:
                coders[demon.feature_key] = StateCoder(demon.features, *plan.plane, list(plan.sensors), plan.bounds)
        stages = []
        for stage, keys in enumerate(by_stage):
            groups = tuple(
                self._compile_group(stage, coders[key], action_values, members)
                for (key, action_values), members in keys.items()
            )
            demons = np.concatenate([g.demons for g in groups])
            members_plan = [plan.demons[i] for i in demons]
            program = Program(
                [d.cumulant for d in members_plan] + [d.outcome for d in members_plan]
                + [d.continuation for d in members_plan],
                sensor_index,
                self.index,
            )  # fmt: skip
            stages.append(Stage(groups, demons, program, np.array([d.discount for d in members_plan])))
        return tuple(stages)

    def _compile_group(self, stage: int, coder: StateCoder, action_values: bool, members: list[int]) -> Group:
        """The demons of one stage over one feature set: blocks of one learner, step-size mode, lambda and policy
        kind, their demons ordered by trace class."""
        by_block: dict[tuple[str, float, BlockPolicy, str], list[int]] = {}
        for i in members:
            d = self.plan.demons[i]
            own: BlockPolicy = "given"
            if d.action_values and d.policy.kind in ("greedy", "softmax", "epsilon_greedy"):
                own = d.policy.kind
            by_block.setdefault((d.learner, d.lam, own, d.step_size), []).append(i)
        first_block, first_class = len(self._blocks), len(self._class_kind)
        slots = []
        for (learner, lam, own, step_size), block_members in by_block.items():
            ordered, block_classes = self._add_classes(block_members, own)
            demons = [self.plan.demons[i] for i in ordered]
            self._blocks.append(
                Block(
                    learner=learner,
                    alpha=np.array([d.alpha for d in demons]) / coder.k,
                    alpha_w=np.array([d.alpha_w for d in demons]) / coder.k,
                    lam=lam,
                    policy=own,
                    classes=block_classes,
                    temperature=np.array([d.policy.temperature for d in demons]),
                    epsilon=np.array([d.policy.epsilon for d in demons]),
                    step_size=step_size,
                    meta=np.array([d.meta for d in demons]),
                    beta=np.array([d.beta for d in demons]),
                )
            )
            slots.extend(ordered)
        condition = coder.spec.condition
        return Group(
            stage=stage,
            coder=coder,
            action_values=action_values,
            condition=self.index[condition.demon] if condition else -1,
            demons=np.array(slots, dtype=np.int64),
            blocks=range(first_block, len(self._blocks)),
            classes=range(first_class, len(self._class_kind)),
        )

    def _add_classes(self, members: list[int], own: BlockPolicy) -> tuple[list[int], np.ndarray | None]:
        """Register the trace classes of one block's demons; returns the demons in class order and each
        one's class within the block (None for own-value demons: each is its own class)."""
        A = self.num_actions
        if own != "given":
            for i in members:
                self._class_kind.append(KIND_CODES[str(own)])
                self._class_fixed.append(np.full(A, 1.0 / A))
                self._class_of.append(-1)
                self._class_demon.append(i)
            return members, None
        order, classes = trace_classes([_trace_key(self.plan.demons[i]) for i in members])
        ordered = [members[j] for j in order]
        for j in np.flatnonzero(np.diff(classes, prepend=-1)):
            policy = self.plan.demons[ordered[j]].policy
            kind = KIND_CODES[policy.kind]
            self._class_kind.append(kind if kind in (FIXED, OF) else UNIFORM)
            probs = policy.probabilities if kind == FIXED and policy.probabilities else [1.0 / A] * A
            self._class_fixed.append(np.asarray(probs, dtype=float))
            self._class_of.append(self.index[policy.demon] if kind == OF and policy.demon else -1)
            self._class_demon.append(ordered[j])
        return ordered, classes

    # ------------------------------------------------------------------------------------------
    # State

    def initial_theta(self) -> tuple[np.ndarray, ...]:
        """Per block [n_b, Db] the primary weights demons start from: their `initial_weights`, else 0."""
        weights = tuple(np.zeros((int(r), b.size)) for r, b in zip(self.block_rows, self.blocks, strict=True))
        for demon in self.demons:
            if demon.initial_weights is not None:
                b, col = self.locate(demon.name)
                weights[b][:, col] = demon.initial_weights  # row a * n + i of GQ's blocks: action a, feature i
        return weights

    def init_state(self) -> HordeState:
        """Weights at their initial values (`initial_theta`: 0 unless a demon sets them), traces zero, nothing
        observed yet."""
        d, c, A = self.num_demons, self.num_classes, self.num_actions
        weights = self.initial_theta()
        return HordeState(
            theta=weights,
            w=tuple(np.zeros_like(a) for a in weights),
            e=tuple(np.zeros((int(r), b.num_classes)) for r, b in zip(self.block_rows, self.blocks, strict=True)),
            h=tuple(np.zeros_like(a) for a in weights),
            delta_e=tuple(np.zeros_like(a) for a in weights),
            delta_e_scale=np.ones(len(self.groups)),
            rupee_dot=np.zeros(d),
            tau=np.zeros((len(self.groups), 2)),
            delta_stats=np.zeros((d, 3)),
            features=tuple(np.zeros(g.coder.k, dtype=np.int64) for g in self.groups),
            class_gamma=np.zeros(c),
            class_pi=np.full((c, A), 1.0 / A),
            pi=np.full((d, A), 1.0 / A),
            q=np.full((d, A), np.nan),
            prediction=np.zeros(d),
            gamma=np.zeros(d),
            delta=np.zeros(d),
            cumulant=np.zeros(d),
            diverged=np.zeros(d, dtype=bool),
            feature_values=tuple(np.zeros(g.coder.k) for g in self.groups),
        )

    def locate(self, name: str) -> tuple[int, int]:
        """(block number, column) of a demon."""
        slot = int(self.demon_slot[self.index[name]])
        b = int(np.searchsorted(self.block_lo, slot, side="right")) - 1
        return b, slot - int(self.block_lo[b])

    def carry_over(self, old: Horde, old_state: HordeState) -> HordeState:
        """A state for this Horde that keeps the weights of every demon `old` also had (by name).

        Demons join and leave a live run this way without disturbing the others' weights; traces
        restart, as at an episode start (observe the position afresh before learning).
        """
        state = self.init_state()
        for name in self.names:
            if name not in old.index:
                continue
            b, col = self.locate(name)
            ob, ocol = old.locate(name)
            if old_state.theta[ob].shape[0] != state.theta[b].shape[0]:
                continue
            for new_arrays, old_arrays in (
                (state.theta, old_state.theta),
                (state.w, old_state.w),
                (state.h, old_state.h),
            ):
                new_arrays[b][:, col] = old_arrays[ob][:, ocol]
            scale = old_state.delta_e_scale[old.block_group[ob]]  # the new state's scale is 1
            state.delta_e[b][:, col] = old_state.delta_e[ob][:, ocol] * scale
            i, oi = self.index[name], old.index[name]
            state.rupee_dot[i] = old_state.rupee_dot[oi] * scale
            state.delta_stats[i] = old_state.delta_stats[oi]
            state.diverged[i] = old_state.diverged[oi]
        tau = old_state.tau[0] if len(old_state.tau) else np.zeros(2)
        return state._replace(tau=np.tile(tau, (len(self.groups), 1)))

    # ------------------------------------------------------------------------------------------
    # Frozen evaluation of a batch of positions

    def _block_values(self, group: Group, theta: np.ndarray, idx: np.ndarray, val: np.ndarray) -> np.ndarray:
        """Action values [B, Db, A] (GQ) or state values [B, Db] of a block's weights theta [rows, Db] at the
        active features (idx, val) [B, k]."""
        if group.action_values:
            n_s = group.coder.n
            return np.stack([(theta[idx + a * n_s] * val[..., None]).sum(axis=1) for a in range(self.num_actions)],
                            axis=-1)  # fmt: skip
        return (theta[idx] * val[..., None]).sum(axis=1)

    def needs(self, names: list[str]) -> np.ndarray:
        """[D] bool: the demons named and every demon they read (predictions, policies, conditions)."""
        wanted = np.zeros(self.num_demons, dtype=bool)
        todo = [self.index[n] for n in names]
        while todo:
            i = todo.pop()
            if not wanted[i]:
                wanted[i] = True
                todo.extend(self.index[d] for d in self.demons[i].dependencies)
        return wanted

    def forward(
        self,
        state: HordeState,
        x: np.ndarray,
        y: np.ndarray,
        sensors: np.ndarray | None = None,
        demons: list[str] | None = None,
    ) -> Forward:
        """Predictions, policies and action values of the demons at a batch of positions, frozen.

        Args:
            state: the Horde's state (its primary weights and per-demon arrays are read).
            x, y: [B] positions.
            sensors: [B, S] the sensors there, for features tiled over sensors (default: what the sensors
                read at an episode's first state at each position, `World.start_sensors`).
            demons: compute only these demons and those they read (default all); the other columns of
                the result stay 0 (prediction), uniform (pi) and nan (q).
        """
        batch, A = len(x), self.num_actions
        wanted = self.needs(demons) if demons is not None else np.ones(self.num_demons, dtype=bool)
        if sensors is None and any(g.coder.spec.kind not in POSITION_KINDS for g in self.groups):
            sensors = self._start_sensors(np.asarray(x, float), np.asarray(y, float))
        prediction = np.zeros((batch, self.num_demons))
        pi = np.full((batch, self.num_demons, A), 1.0 / A)
        q = np.full((batch, self.num_demons, A), np.nan)
        features: list[np.ndarray] = []
        for group in self.groups:
            if not wanted[group.demons].any():
                features.append(np.zeros((batch, group.coder.k), dtype=np.int64))
                continue
            condition = prediction[:, group.condition] if group.condition >= 0 else None
            idx, val = group.coder.sparse(x, y, condition, sensors)  # [B, k] each
            features.append(idx)
            lo = 0
            for b in group.blocks:
                block = self.blocks[b]
                members = group.demons[lo : lo + block.size]
                classes = self.slot_class[self.block_lo[b] : self.block_lo[b] + block.size]
                lo += block.size
                keep = wanted[members]
                if not keep.any():
                    continue
                members, classes = members[keep], classes[keep]
                values = self._block_values(group, state.theta[b] if keep.all() else state.theta[b][:, keep], idx, val)
                if block.policy != "given":
                    kinds = np.full(len(members), POLICY_CODES[block.policy])
                    temperature, epsilon = np.asarray(block.temperature)[keep], np.asarray(block.epsilon)[keep]
                    pi_b = value_policy(values, kinds, temperature, epsilon)
                else:
                    pi_b = np.repeat(self.class_fixed[classes][None], batch, axis=0)  # [B, Db, A]
                    follows = self.class_of[classes]
                    if (follows >= 0).any():
                        pi_b[:, follows >= 0] = pi[:, follows[follows >= 0]]
                pi[:, members] = pi_b
                if group.action_values:
                    q[:, members] = values
                    prediction[:, members] = (pi_b * values).sum(axis=-1)
                else:
                    prediction[:, members] = values
        return Forward(prediction, pi, q, tuple(features))

    def _start_sensors(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """[B, S] what the sensors read at an episode's first state at each position (no colour shown)."""
        world = World(self.spec.grid)
        colors = np.zeros((len(x), world.num_indicators), dtype=np.int64)
        return world.start_sensors(WorldState(x, y, np.zeros(len(x), np.int64), colors))

    # ------------------------------------------------------------------------------------------
    # Behaviour

    def behaviour_probs(self, q: np.ndarray, behaviour: BehaviourSpec | None = None) -> np.ndarray:
        """b(. | s) for a batch: q is [B, D, A] action values of all demons; returns [B, A]."""
        behaviour = behaviour or self.behaviour
        batch, A = q.shape[0], self.num_actions
        if behaviour.kind == "uniform":
            return np.full((batch, A), 1.0 / A)
        if behaviour.kind == "fixed":
            return np.broadcast_to(np.asarray(behaviour.probabilities, dtype=float), (batch, A)).copy()
        assert behaviour.demon is not None
        values = q[:, self.index[behaviour.demon]][:, None, :]  # [B, 1, A]
        kind = np.array([KIND_CODES[behaviour.kind]])
        probs = value_policy(values, kind, np.array([behaviour.temperature]), np.array([behaviour.epsilon]))
        return probs[:, 0, :]

    # ------------------------------------------------------------------------------------------
    # Reading out

    def _per_demon(self, per_block: list[np.ndarray]) -> np.ndarray:
        out = np.zeros(self.num_demons)
        if per_block:
            out[self.slot_demon] = np.concatenate(per_block)
        return out

    def rupee(self, state: HordeState) -> np.ndarray:
        """[D] sqrt(|h . average(delta e)|) (metrics.py), from the dot products the engine keeps."""
        scale = np.zeros(self.num_demons)
        for group, s in zip(self.groups, state.delta_e_scale, strict=True):
            scale[group.demons] = s
        return np.sqrt(np.abs(scale * state.rupee_dot))

    def ude(self, state: HordeState) -> np.ndarray:
        return metrics.ude_of(state.delta_stats)

    def weights(self, state: HordeState, name: str) -> np.ndarray:
        """The primary weights of one demon (a copy)."""
        b, col = self.locate(name)
        return state.theta[b][:, col].copy()

    def demon_arrays(self, state: HordeState, name: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """One demon's (theta, w, e), each [n] (views): the demon-major view that reference.py keeps."""
        b, col = self.locate(name)
        slot = int(self.demon_slot[self.index[name]])
        trace = int(self.slot_class[slot] - self.slot_class[self.block_lo[b]])
        return state.theta[b][:, col], state.w[b][:, col], state.e[b][:, trace]

    @property
    def keeps_learner_state(self) -> bool:
        """Whether any demon's learner keeps numbers beyond `HordeState` (true online TD / GTD, emphatic TD, an
        adaptive step size, tdrc's scale of h: `Kernel.keeps_state`)."""
        return any(b.kernel.keeps_state for b in self.blocks)

    def is_control(self, name: str) -> bool:
        demon = self.demons[self.index[name]]
        return demon.action_values and KIND_CODES[demon.policy.kind] in OWN_VALUE

    def prediction_demons(self) -> list[str]:
        """Demons whose prediction is a question's answer (not the control demons)."""
        return [name for name in self.names if not self.is_control(name)]
