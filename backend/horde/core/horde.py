"""The Horde: demons grouped into stacks, run in dependency order, one learning step for all.

Demons that share a feature spec, a kind of value (action values for GQ, state values for GTD/TD)
and a dependency stage form a group whose weights are stacked arrays [D, n]; a step is a handful of
array operations per group, not a loop over demons. Stage s holds the demons whose inputs (predictions
as cumulants, policies of other demons, conditioned features) come from stages before s, so that a
prediction read by another demon is the one for s_{t+1} after its owner's update at this step.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from horde.core import learners, metrics
from horde.core.features import StateCoder
from horde.core.policies import KIND_CODES, OF, OWN_VALUE, UNIFORM, value_policy
from horde.core.questions import Program
from horde.core.world import NUM_ACTIONS
from horde.spec import BehaviourSpec, DemonSpec, FeatureSpec, RunSpec, check_demon_graph, demon_dependencies


@dataclass(frozen=True)
class Group:
    """A stack of demons that learn with one set of array operations."""

    stage: int
    demons: np.ndarray  # [Dg] global demon indices
    coder: StateCoder
    action_values: bool
    num_features: int  # n: A * coder.n for action values, coder.n otherwise
    params: learners.LearnerParams
    policy_kind: np.ndarray  # [Dg] policy kind codes
    fixed: np.ndarray  # [Dg, A] probabilities of uniform/fixed policies
    temperature: np.ndarray  # [Dg]
    epsilon: np.ndarray  # [Dg]
    of_index: np.ndarray  # [Dg] global index of the demon followed (or -1)
    reset: np.ndarray  # [Dg] bool: forget the weights at every episode start
    condition: int  # global index of the condition demon, or -1
    own_value: np.ndarray  # [Dg] bool: greedy / softmax / epsilon-greedy over own action values
    follows: np.ndarray  # [Dg] bool: the policy of another demon


@dataclass(frozen=True)
class Stage:
    groups: tuple[Group, ...]
    demons: np.ndarray  # [Ds] global indices, in the program's column order
    program: Program  # 3 * Ds outputs: cumulants, outcomes, continuations
    discount: np.ndarray  # [Ds]


class HordeState(NamedTuple):
    """Everything that changes while a Horde learns (one agent)."""

    learners: tuple[learners.LearnerState, ...]  # per group
    metrics: tuple[metrics.MetricsState, ...]  # per group
    features: tuple[np.ndarray, ...]  # per group: [k] active state features at s_t
    pi: np.ndarray  # [D, A] target policy at s_t
    q: np.ndarray  # [D, A] action values at s_t (nan for state-value demons)
    prediction: np.ndarray  # [D] prediction at s_t
    gamma: np.ndarray  # [D] continuation at s_t
    delta: np.ndarray  # [D] last TD error
    cumulant: np.ndarray  # [D] last cumulant
    diverged: np.ndarray  # [D] bool: weights went non-finite, frozen since


class Forward(NamedTuple):
    """What the frozen Horde says about a batch of positions."""

    prediction: np.ndarray  # [B, D]
    pi: np.ndarray  # [B, D, A]
    q: np.ndarray  # [B, D, A] (nan for state-value demons)
    features: tuple[np.ndarray, ...]  # per group [B, k]


class Horde:
    """A compiled set of demons over one world.

    Args:
        spec: the run spec (its world, default features, learning defaults, behaviour and demons).
    """

    def __init__(self, spec: RunSpec) -> None:
        self.spec = spec
        self.demon_specs: list[DemonSpec] = list(spec.demons)
        self.names = [d.name for d in self.demon_specs]
        self.index = {name: i for i, name in enumerate(self.names)}
        self.num_demons = len(self.names)
        order = check_demon_graph(spec)
        stage_of: dict[str, int] = {}
        for name in order:
            deps = demon_dependencies(self.demon_specs[self.index[name]], spec.features)
            stage_of[name] = 1 + max((stage_of[d] for d in deps), default=-1)
        self.stage_of = np.array([stage_of[n] for n in self.names], dtype=np.int64)
        self.is_action_value = np.array([d.learner == "gq" for d in self.demon_specs])
        self.stages = self._compile_stages(spec, stage_of)
        self.groups: tuple[Group, ...] = tuple(g for stage in self.stages for g in stage.groups)
        self.behaviour = spec.behaviour
        self.behaviour_demon = self.index[spec.behaviour.demon] if spec.behaviour.demon else -1

    # ------------------------------------------------------------------------------------------
    # Compilation

    def _compile_stages(self, spec: RunSpec, stage_of: dict[str, int]) -> tuple[Stage, ...]:
        world = spec.world
        stages = []
        for stage in range(max(stage_of.values(), default=-1) + 1):
            keys: dict[tuple[str, bool], list[int]] = {}
            features_of: dict[str, FeatureSpec] = {}
            for i, demon in enumerate(self.demon_specs):
                if stage_of[demon.name] == stage:
                    features = demon.features or spec.features
                    key = features.model_dump_json()
                    features_of[key] = features
                    keys.setdefault((key, demon.learner == "gq"), []).append(i)
            groups = tuple(
                self._compile_group(spec, stage, features_of[key], action_values, members)
                for (key, action_values), members in keys.items()
            )
            demons = np.concatenate([g.demons for g in groups])
            specs = [self.demon_specs[i] for i in demons]
            sensor_index = {name: i for i, name in enumerate(world.sensor_names())}
            program = Program(
                [d.cumulant for d in specs] + [d.outcome for d in specs] + [d.continuation for d in specs],
                sensor_index,
                self.index,
            )
            discount = np.array([d.discount for d in specs])
            stages.append(Stage(groups, demons, program, discount))
        return tuple(stages)

    def _compile_group(
        self, spec: RunSpec, stage: int, features: FeatureSpec, action_values: bool, members: list[int]
    ) -> Group:
        coder = StateCoder(features, spec.world.width, spec.world.height)
        demons = [self.demon_specs[i] for i in members]
        defaults = spec.learning
        lam = np.array([d.lambda_ if d.lambda_ is not None else defaults.lambda_ for d in demons])
        alpha = np.array([d.alpha if d.alpha is not None else defaults.alpha for d in demons]) / coder.k
        alpha_w = np.array([d.alpha_w if d.alpha_w is not None else defaults.alpha_w for d in demons]) / coder.k
        params = learners.LearnerParams(
            lam=lam,
            alpha=alpha,
            alpha_w=alpha_w,
            rho_in_trace=np.array([0.0 if d.learner == "gq" else 1.0 for d in demons]),
            correct=np.array([0.0 if d.learner == "td" else 1.0 for d in demons]),
        )
        fixed = np.full((len(demons), NUM_ACTIONS), 1.0 / NUM_ACTIONS)
        for row, d in enumerate(demons):
            if d.policy.kind == "fixed" and d.policy.probabilities is not None:
                fixed[row] = d.policy.probabilities
        condition = features.condition
        policy_kind = np.array([KIND_CODES[d.policy.kind] for d in demons])
        return Group(
            stage=stage,
            demons=np.array(members, dtype=np.int64),
            coder=coder,
            action_values=action_values,
            num_features=coder.n * (NUM_ACTIONS if action_values else 1),
            params=params,
            policy_kind=policy_kind,
            fixed=fixed,
            temperature=np.array([d.policy.temperature for d in demons]),
            epsilon=np.array([d.policy.epsilon for d in demons]),
            of_index=np.array(
                [self.index[d.policy.demon] if d.policy.kind == "of" and d.policy.demon else -1 for d in demons]
            ),
            reset=np.array([d.reset == "episode" for d in demons]),
            condition=self.index[condition.demon] if condition else -1,
            own_value=np.isin(policy_kind, OWN_VALUE) & action_values,
            follows=policy_kind == OF,
        )

    # ------------------------------------------------------------------------------------------
    # State

    def init_state(self) -> HordeState:
        """All weights and traces zero; call `start_episode` before learning."""
        d = self.num_demons
        return HordeState(
            learners=tuple(learners.zeros(len(g.demons), g.num_features) for g in self.groups),
            metrics=tuple(metrics.zeros(len(g.demons), g.num_features) for g in self.groups),
            features=tuple(np.zeros(g.coder.k, dtype=np.int64) for g in self.groups),
            pi=np.full((d, NUM_ACTIONS), 1.0 / NUM_ACTIONS),
            q=np.full((d, NUM_ACTIONS), np.nan),
            prediction=np.zeros(d),
            gamma=np.zeros(d),
            delta=np.zeros(d),
            cumulant=np.zeros(d),
            diverged=np.zeros(d, dtype=bool),
        )

    def start_episode(self, state: HordeState, x: float, y: float) -> HordeState:
        """Traces to zero, reset-each-episode demons forget, and the Horde observes the first state."""
        new_learners = []
        for group, learner in zip(self.groups, state.learners, strict=True):
            theta, w = learner.theta, learner.w
            if group.reset.any():
                keep = ~group.reset[:, None]
                theta, w = np.where(keep, theta, 0.0), np.where(keep, w, 0.0)
            new_learners.append(learners.LearnerState(theta, w, np.zeros_like(learner.e)))
        state = state._replace(learners=tuple(new_learners), gamma=np.zeros(self.num_demons))
        return self.observe(state, x, y)

    def observe(self, state: HordeState, x: float, y: float) -> HordeState:
        """The state with every demon's features, policy, action values and prediction at (x, y)."""
        forward = self.forward(state, np.array([x]), np.array([y]))
        return state._replace(
            features=tuple(f[0] for f in forward.features),
            pi=forward.pi[0],
            q=forward.q[0],
            prediction=forward.prediction[0],
        )

    # ------------------------------------------------------------------------------------------
    # Frozen evaluation of a batch of positions

    def _group_values(self, group: Group, theta: np.ndarray, idx: np.ndarray) -> np.ndarray:
        """Action values [B, Dg, A] or state values [B, Dg] of a batch of active state features [B, k]."""
        if group.action_values:
            blocks = theta.reshape(len(group.demons), NUM_ACTIONS, group.coder.n)  # [Dg, A, n_s]
            return blocks[:, :, idx].sum(axis=-1).transpose(2, 0, 1)  # [B, Dg, A]
        return theta[:, idx].sum(axis=-1).T  # [B, Dg]

    def _group_policy(self, group: Group, values: np.ndarray, pi_all: np.ndarray) -> np.ndarray:
        """Target policies [B, Dg, A]; `pi_all` [B, D, A] holds the policies of earlier stages."""
        batch = values.shape[0]
        own, follows = group.own_value, group.follows
        if own.all():
            return value_policy(values, group.policy_kind, group.temperature, group.epsilon)
        pi = np.repeat(group.fixed[None], batch, axis=0)  # [B, Dg, A]
        if own.any():
            pi[:, own] = value_policy(
                values[:, own], group.policy_kind[own], group.temperature[own], group.epsilon[own]
            )
        if follows.any():
            pi[:, follows] = pi_all[:, group.of_index[follows]]
        return pi

    def _group_predictions(self, group: Group, values: np.ndarray, pi: np.ndarray) -> np.ndarray:
        """[B, Dg]: sum_a pi(a|s) q(s, a) for action values, theta . phi(s) for state values."""
        return (pi * values).sum(axis=-1) if group.action_values else values

    def _group_features(self, group: Group, x: np.ndarray, y: np.ndarray, prediction: np.ndarray) -> np.ndarray:
        condition = prediction[:, group.condition] if group.condition >= 0 else None
        return group.coder.active(x, y, condition)

    def forward(self, state: HordeState, x: np.ndarray, y: np.ndarray) -> Forward:
        """Predictions, policies and action values of every demon at a batch of positions, frozen."""
        batch = len(x)
        prediction = np.zeros((batch, self.num_demons))
        pi = np.full((batch, self.num_demons, NUM_ACTIONS), 1.0 / NUM_ACTIONS)
        q = np.full((batch, self.num_demons, NUM_ACTIONS), np.nan)
        features: list[np.ndarray] = []
        for group, learner in zip(self.groups, state.learners, strict=True):
            idx = self._group_features(group, x, y, prediction)
            values = self._group_values(group, learner.theta, idx)
            pi_g = self._group_policy(group, values, pi)
            pi[:, group.demons] = pi_g
            if group.action_values:
                q[:, group.demons] = values
            prediction[:, group.demons] = self._group_predictions(group, values, pi_g)
            features.append(idx)
        return Forward(prediction, pi, q, tuple(features))

    # ------------------------------------------------------------------------------------------
    # Behaviour

    def behaviour_probs(self, q: np.ndarray, behaviour: BehaviourSpec | None = None) -> np.ndarray:
        """b(. | s) for a batch: q is [B, D, A] action values of all demons; returns [B, A]."""
        behaviour = behaviour or self.behaviour
        batch = q.shape[0]
        if behaviour.kind == "uniform":
            return np.full((batch, NUM_ACTIONS), 1.0 / NUM_ACTIONS)
        if behaviour.kind == "fixed":
            return np.broadcast_to(np.asarray(behaviour.probabilities, dtype=float), (batch, NUM_ACTIONS)).copy()
        assert behaviour.demon is not None
        values = q[:, self.index[behaviour.demon]][:, None, :]  # [B, 1, A]
        kind = np.array([KIND_CODES[behaviour.kind]])
        probs = value_policy(values, kind, np.array([behaviour.temperature]), np.array([behaviour.epsilon]))
        return probs[:, 0, :]

    # ------------------------------------------------------------------------------------------
    # Learning

    def learn(
        self,
        state: HordeState,
        action: int,
        b_prob: float,
        x_tp1: float,
        y_tp1: float,
        sensors_tp1: np.ndarray,
        terminated: bool,
        with_metrics: bool = True,
        learning: np.ndarray | None = None,
    ) -> HordeState:
        """One transition (s_t, a_t) -> s_{t+1} for every demon, stage by stage.

        Args:
            state: the Horde at s_t.
            action: a_t.
            b_prob: b(a_t | s_t), the behaviour's probability of the action taken.
            x_tp1, y_tp1: the next position.
            sensors_tp1: [S] sensors at s_{t+1}.
            terminated: whether s_{t+1} ends the episode (every continuation is then 0).
            with_metrics: update RUPEE / UDE averages.
            learning: [D] bool, which demons learn (default all); the others keep their weights.

        Returns:
            The Horde at s_{t+1}.
        """
        x = np.array([x_tp1])
        y = np.array([y_tp1])
        sensors = sensors_tp1[None, :]  # [1, S]
        prediction = state.prediction.copy()[None, :]  # [1, D], filled with s_{t+1} stage by stage
        pi = state.pi.copy()[None, :, :]  # [1, D, A]
        q = state.q.copy()
        gamma = state.gamma.copy()
        delta = state.delta.copy()
        cumulant = state.cumulant.copy()
        diverged = state.diverged.copy()
        new_learners = list(state.learners)
        new_metrics = list(state.metrics)
        new_features = list(state.features)
        group_number = 0
        for stage in self.stages:
            answers = stage.program.evaluate(sensors, prediction)[0]  # [3 Ds]
            ds = len(stage.demons)
            r_stage, z_stage = answers[:ds], answers[ds : 2 * ds]
            gamma_stage = np.minimum(np.maximum(answers[2 * ds :], 0.0), 1.0) * stage.discount
            if terminated:
                gamma_stage = np.zeros(ds)
            offset = 0
            for group in stage.groups:
                g = group_number
                group_number += 1
                rows = slice(offset, offset + len(group.demons))
                offset += len(group.demons)
                members = group.demons
                old = state.learners[g]
                idx_t = state.features[g]  # [k]
                idx_tp1 = self._group_features(group, x, y, prediction)  # [1, k]
                values_old = self._group_values(group, old.theta, idx_tp1)
                pi_tp1 = self._group_policy(group, values_old, pi)[0]  # [Dg, A]
                rho = state.pi[members, action] / b_prob  # [Dg]
                ones = np.ones(group.coder.k)
                if group.action_values:
                    n_s = group.coder.n
                    x_t = (idx_t + action * n_s, ones)
                    bar_idx = (idx_tp1[0][None, :] + (np.arange(NUM_ACTIONS) * n_s)[:, None]).ravel()  # [A k]
                    bar_val = np.repeat(pi_tp1, group.coder.k, axis=1)  # [Dg, A k]
                    x_bar = (bar_idx, bar_val)
                else:
                    x_t = (idx_t, ones)
                    x_bar = (idx_tp1[0], ones)
                r = r_stage[rows]
                new, delta_g = learners.update(
                    old, group.params, x_t, x_bar, r, z_stage[rows], state.gamma[members], gamma_stage[rows], rho
                )
                nonfinite = ~np.isfinite(new.theta).all(axis=1) | ~np.isfinite(new.w).all(axis=1)
                diverged[members] |= nonfinite
                frozen = diverged[members] if learning is None else diverged[members] | ~learning[members]
                if frozen.any():
                    keep = frozen[:, None]
                    new = learners.LearnerState(
                        np.where(keep, old.theta, new.theta), np.where(keep, old.w, new.w), np.where(keep, old.e, new.e)
                    )
                new_learners[g] = new
                if with_metrics:
                    new_metrics[g] = metrics.update(state.metrics[g], delta_g, new.e, *x_t, group.coder.k)
                values_new = self._group_values(group, new.theta, idx_tp1)
                pi_new = self._group_policy(group, values_new, pi)  # [1, Dg, A]
                pi[:, members] = pi_new
                if group.action_values:
                    q[members] = values_new[0]
                prediction[:, members] = self._group_predictions(group, values_new, pi_new)
                new_features[g] = idx_tp1[0]
                gamma[members] = gamma_stage[rows]
                delta[members] = delta_g
                cumulant[members] = r
        return HordeState(
            learners=tuple(new_learners),
            metrics=tuple(new_metrics),
            features=tuple(new_features),
            pi=pi[0],
            q=q,
            prediction=prediction[0],
            gamma=gamma,
            delta=delta,
            cumulant=cumulant,
            diverged=diverged,
        )

    def carry_over(self, old: Horde, old_state: HordeState, x: float, y: float) -> HordeState:
        """A state for this Horde that keeps the weights of every demon `old` also had (by name).

        Demons join and leave a live run this way without disturbing the others' weights; traces
        restart, as at an episode start, and the Horde observes (x, y) afresh.
        """
        state = self.init_state()
        new_learners = list(state.learners)
        new_metrics = list(state.metrics)
        for g, group in enumerate(self.groups):
            theta, w = new_learners[g].theta.copy(), new_learners[g].w.copy()
            metric = new_metrics[g]
            h, delta_e = metric.h.copy(), metric.delta_e.copy()
            for row, demon in enumerate(group.demons):
                name = self.names[demon]
                if name not in old.index:
                    continue
                og, orow = old.locate(name)
                if old.groups[og].num_features != group.num_features:
                    continue
                theta[row] = old_state.learners[og].theta[orow]
                w[row] = old_state.learners[og].w[orow]
                h[row] = old_state.metrics[og].h[orow]
                delta_e[row] = old_state.metrics[og].delta_e[orow]
            new_learners[g] = learners.LearnerState(theta, w, np.zeros_like(theta))
            new_metrics[g] = metric._replace(h=h, delta_e=delta_e)
        diverged = np.array([bool(old_state.diverged[old.index[n]]) if n in old.index else False for n in self.names])
        state = state._replace(learners=tuple(new_learners), metrics=tuple(new_metrics), diverged=diverged)
        return self.observe(state, x, y)

    def locate(self, name: str) -> tuple[int, int]:
        """(group number, row) of a demon."""
        i = self.index[name]
        for g, group in enumerate(self.groups):
            rows = np.nonzero(group.demons == i)[0]
            if len(rows):
                return g, int(rows[0])
        raise KeyError(name)

    # ------------------------------------------------------------------------------------------
    # Reading out

    def rupee(self, state: HordeState) -> np.ndarray:
        out = np.zeros(self.num_demons)
        for group, m in zip(self.groups, state.metrics, strict=True):
            out[group.demons] = metrics.rupee(m)
        return out

    def ude(self, state: HordeState) -> np.ndarray:
        out = np.zeros(self.num_demons)
        for group, m in zip(self.groups, state.metrics, strict=True):
            out[group.demons] = metrics.ude(m)
        return out

    def weights(self, state: HordeState, name: str) -> np.ndarray:
        """The primary weights of one demon (a copy)."""
        g, row = self.locate(name)
        return state.learners[g].theta[row].copy()

    def is_control(self, name: str) -> bool:
        demon = self.demon_specs[self.index[name]]
        return demon.learner == "gq" and KIND_CODES[demon.policy.kind] in OWN_VALUE

    def prediction_demons(self) -> list[str]:
        """Demons whose prediction is a question's answer (not the control demons)."""
        return [name for name in self.names if not self.is_control(name)]


__all__ = ["UNIFORM", "Forward", "Group", "Horde", "HordeState", "Stage"]
