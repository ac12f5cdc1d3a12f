"""The one engine fed from outside: learn from transitions whose sensors someone else observed.

The grid world is simulated inside the compiled loop (`fast._run`). Every other world kind (a Gymnasium
environment stepped in Python, a live stream of pushed records, a recorded log read at full speed) feeds
the same compiled Horde through this one input path:

* `observe(sensors)`: an episode starts at a state with these sensors (traces restart, DESIGN section 5);
* `learn(sensors_tp1, actions, b_probs, terminated, truncated)`: the transitions
  (s_t, a_t) -> s_{t+1}, s_{t+1} -> s_{t+2}, ... one per row, with b(a_t | s_t) of each action taken.
  Only the last row may end an episode; then the caller observes the next episode's first state.

The learning step is the grid loop's, with the world's move replaced by the given sensors: the same
stage-by-stage question programs, feature coding, block kernels (`scale_fast._step`), divergence freeze
and RUPEE/UDE metrics. Features must be tiled over sensors (or constant): there is no grid position.
Tests check that feeding the grid world's own transitions here gives the grid loop's numbers exactly.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import ArrayLike

from horde.core.adaptive_kernels import online_reset, online_step
from horde.core.fast import (
    G_BHI,
    G_BLO,
    G_CHI,
    G_CLO,
    G_COND,
    G_K,
    G_NS,
    G_SHI,
    G_SLO,
    G_STAGE,
    FastLoop,
    _any_diverged,
    _evaluate,
    _features,
    _freeze_diverged,
    _given_policies,
    _given_to_slots,
    _metrics,
    _observe,
    _sort,
    _step,
)
from horde.core.horde import Horde, HordeState
from horde.core.scale_fast import B_LEARNER, ONLINE, _read_values
from horde.core.world import World
from horde.spec import BehaviourSpec, WorldSpec


class ExternalRecordError(ValueError):
    """A transition the engine cannot learn from (the message names the field: sensors, action, b_prob)."""


@njit(cache=True)
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


@njit(cache=True, nogil=True)
def _learn_rows(net, buf, onl, rules, sensors_tp1, actions, b_probs, terminated, with_metrics, pred_out):
    """Learn from each row's transition in order (the learning half of `fast._run`, position 0, 0).

    pred_out: [T, D] the predictions (slot order) after each row, or [0, D] to keep none.
    """
    gi, bi, lam, dcls, cls_lo, cls_hi = net.gi, net.bi, net.lam, net.dcls, net.cls_lo, net.cls_hi
    feat, idx, node_values = buf.feat, buf.idx, buf.node_values
    class_pi, pi_given, gamma_tp1, rho = buf.class_pi, buf.pi_given, buf.gamma_tp1, buf.rho
    r_s, z_s, pi, q, pred = buf.r, buf.z, buf.pi, buf.q, buf.pred
    hx = np.zeros(2 * max(1, buf.work.shape[1]))
    A = pi.shape[1]
    sensors = buf.sensors
    for t in range(sensors_tp1.shape[0]):
        sensors[:] = sensors_tp1[t]
        action = actions[t]
        b_prob = b_probs[t]
        ended = terminated[t]
        _apply_rules(rules, sensors, net.class_fixed)
        current_stage = -1
        for g in range(gi.shape[0]):
            stage = gi[g, G_STAGE]
            if stage != current_stage:
                current_stage = stage
                _evaluate(net.stage_lo[stage], net.stage_hi[stage], net.node_kind, net.node_arg, net.node_start,
                          net.node_children, sensors, pred, node_values)  # fmt: skip
            k = gi[g, G_K]
            cond = pred[gi[g, G_COND]] if gi[g, G_COND] >= 0 else 0.0
            _features(gi, net.thresholds, net.tiled_col, net.tiled_low, net.tiled_high, buf.tiled_values, g, 0.0, 0.0,
                      sensors, cond, net.wp, idx)  # fmt: skip
            _sort(idx, k)
            clo, chi = gi[g, G_CLO], gi[g, G_CHI]
            for c in range(clo, chi):
                g1 = min(max(node_values[net.class_gnode[c]], 0.0), 1.0) * net.class_discount[c]
                gamma_tp1[c] = 0.0 if ended else g1
                rho[c] = class_pi[c, action] / b_prob
            _given_policies(gi, net.class_kind, net.class_of, net.class_fixed, pi, pi_given, g)
            slo, shi = gi[g, G_SLO], gi[g, G_SHI]
            for s in range(slo, shi):
                r_s[s] = node_values[net.out_r[s]]
                z_s[s] = node_values[net.out_z[s]]
            blo, bhi = gi[g, G_BLO], gi[g, G_BHI]
            _step(
                bi[blo:bhi], lam[blo:bhi], buf.alpha_now, buf.alpha_w_now, net.temperature, net.epsilon, dcls, cls_lo,
                cls_hi, net.cut, gi[g, G_NS], buf.theta, buf.w, buf.trace, buf.support, buf.rows, buf.rows_e,
                buf.rows_f, buf.nnz[blo:bhi], feat[g, :k], action, b_prob, idx[:k], r_s, z_s, gamma_tp1, rho,
                pi_given, buf.class_gamma, q, pi, pred, buf.delta, buf.touched[blo:bhi], buf.values, buf.pi_next,
                buf.work[0], buf.work[1], buf.work[2], buf.work[3], buf.ev, buf.work[4], buf.work[5], buf.scratch[0],
                buf.scratch[1],
            )  # fmt: skip
            for ob in range(blo, bhi):  # the learners of adaptive_kernels.py, which _step skips
                if bi[ob, B_LEARNER] >= ONLINE:
                    _read_values(bi, ob, gi[g, G_NS], buf.theta, idx[:k], buf.values)
                    online_step(bi, ob, lam[ob], buf.alpha_now, buf.alpha_w_now, dcls, net.cut, buf.theta, buf.w,
                                buf.trace, buf.support, buf.rows, buf.nnz, feat[g, :k], idx[:k], r_s, z_s, gamma_tp1,
                                rho, buf.class_gamma, q, pred, buf.delta, buf.touched, buf.values, onl)  # fmt: skip
            _given_to_slots(gi, bi, dcls, pi, pi_given, g)
            for c in range(clo, chi):
                for a in range(A):
                    class_pi[c, a] = pi_given[c, a]
            for s in range(slo, shi):
                buf.gamma[s] = gamma_tp1[dcls[s]]
                buf.cumulant[s] = r_s[s]
            if _any_diverged(gi, bi, g, buf.delta, pred, q, buf.diverged):
                _freeze_diverged(net, buf, g)
            if with_metrics:
                _metrics(gi, bi, dcls, g, action, feat[g, :k], buf.delta, buf.h, buf.u, buf.hu, buf.mscale, buf.tau,
                         buf.dstats, buf.trace, buf.support, buf.nnz, hx)  # fmt: skip
            for j in range(k):
                feat[g, j] = idx[j]
        if pred_out.shape[0] > 0:
            pred_out[t, :] = pred


class ExternalLoop:
    """A compiled Horde that learns from transitions supplied by the caller.

    Args:
        horde: the compiled demons; its spec's world names the sensors (any kind; features tiled over
            sensors or constant).
    """

    def __init__(self, horde: Horde) -> None:
        self.horde = horde
        self.sensor_names = horde.spec.world.sensor_names()
        self.num_sensors = len(self.sensor_names)
        self.num_actions = horde.num_actions
        grid = horde.spec.world if isinstance(horde.spec.world, WorldSpec) else WorldSpec()
        self.fast = FastLoop(horde, World(grid))  # the grid's own parameters go unused here
        buf = self.fast.buf
        if len(buf.sensors) != self.num_sensors:
            self.fast.buf = buf._replace(sensors=np.zeros(self.num_sensors), start_sensors=np.zeros(self.num_sensors))
        column = {name: i for i, name in enumerate(self.sensor_names)}
        rules = []
        for c, demon in enumerate(horde.class_demon):
            policy = horde.demon_specs[int(demon)].policy
            if policy.kind == "sign" and policy.sensor is not None and policy.actions is not None:
                rules.append([c, column[policy.sensor], policy.actions[0], policy.actions[1], policy.epsilon])
        self._rules = np.array(rules, dtype=float).reshape(-1, 5)  # [R, 5] (see _apply_rules)
        self.with_metrics = True
        self.steps = 0
        self.episodes = 0
        self.set_learning(None)

    def set_learning(self, learning: np.ndarray | None) -> None:
        """Which demons learn ([D] bool, default all); diverged demons stay frozen."""
        buf, net = self.fast.buf, self.fast.net
        live = ~buf.diverged
        if learning is not None:
            live &= np.asarray(learning, dtype=bool)[self.horde.slot_demon]
        buf.alpha_now[:] = np.where(live, net.alpha, 0.0)
        buf.alpha_w_now[:] = np.where(live, net.alpha_w, 0.0)

    def _sensor_rows(self, sensors: np.ndarray) -> np.ndarray:
        rows = np.ascontiguousarray(sensors, dtype=float)
        if rows.ndim == 1:
            rows = rows[None, :]
        if rows.ndim != 2 or rows.shape[1] != self.num_sensors:
            raise ExternalRecordError(f"sensors: {rows.shape[-1]} readings, the world has {self.num_sensors} "
                                      f"({', '.join(self.sensor_names)})")  # fmt: skip
        bad = ~np.isfinite(rows)
        if bad.any():
            row, col = np.argwhere(bad)[0]
            raise ExternalRecordError(f"sensors.{self.sensor_names[col]}: {rows[row, col]} is not a finite number")
        return rows

    def observe(self, sensors: np.ndarray) -> None:
        """An episode starts (or a stream begins) at a state with these sensors [S]: traces restart."""
        rows = self._sensor_rows(sensors)
        self.fast.buf.sensors[:] = rows[0]
        self.fast.buf.start_sensors[:] = rows[0]
        _apply_rules(self._rules, rows[0], self.fast.net.class_fixed)
        _observe(self.fast.net, self.fast.buf)
        online_reset(self.fast.net.bi, self.fast.net.reset, self.fast.net.alpha, self.fast.onl)

    def learn(
        self,
        sensors_tp1: np.ndarray,
        actions: ArrayLike,
        b_probs: ArrayLike,
        terminated: bool = False,
        truncated: bool = False,
        keep_predictions: bool = False,
    ) -> np.ndarray | None:
        """Learn from T transitions in order; only the last may end the episode.

        Args:
            sensors_tp1: [T, S] (or [S]) the sensors after each action.
            actions: [T] the actions a_t, in [0, A).
            b_probs: [T] b(a_t | s_t), in (0, 1].
            terminated: the last transition reached a terminal state (its continuation is 0).
            truncated: the episode was cut after the last transition (it still bootstraps).
            keep_predictions: return [T, D] every demon's prediction after each row (demon order).
        Raises:
            ExternalRecordError: naming the field of the first bad row; nothing is learned then.
        """
        rows = self._sensor_rows(sensors_tp1)
        acts = np.asarray(actions, dtype=np.int64).reshape(-1)
        probs = np.asarray(b_probs, dtype=float).reshape(-1)
        if len(acts) != len(rows) or len(probs) != len(rows):
            raise ExternalRecordError("actions: one action and one behaviour probability per row of sensors")
        if len(acts) and (acts.min() < 0 or acts.max() >= self.num_actions):
            bad = int(acts[(acts < 0) | (acts >= self.num_actions)][0])
            raise ExternalRecordError(
                f"action: {bad} is not one of the world's {self.num_actions} actions (0 to {self.num_actions - 1})"
            )
        if len(probs) and not ((probs > 0.0) & (probs <= 1.0)).all():
            raise ExternalRecordError("behaviour_probabilities: b(a_t | s_t) of the action taken must be in (0, 1]")
        ends = np.zeros(len(rows), dtype=np.bool_)
        if len(rows):
            ends[-1] = terminated
        kept = np.zeros((len(rows) if keep_predictions else 0, self.horde.num_demons))  # [T, D] slot order
        fast = self.fast
        _learn_rows(fast.net, fast.buf, fast.onl, self._rules, rows, acts, probs, ends, self.with_metrics, kept)
        self.steps += len(rows)
        if terminated or truncated:
            self.episodes += 1
        if not keep_predictions:
            return None
        out = np.empty_like(kept)
        out[:, self.horde.slot_demon] = kept
        return out

    # ------------------------------------------------------------------------------------------
    # Reading out

    def q(self) -> np.ndarray:
        """[D, A] action values at the current state (state-value demons: column 0 holds the value)."""
        return self.fast._per_demon(self.fast.buf.q)

    def behaviour_probs(self, behaviour: BehaviourSpec | None = None) -> np.ndarray:
        """[A] b(. | s) at the current state."""
        return self.horde.behaviour_probs(self.q()[None], behaviour)[0]

    def prediction(self) -> np.ndarray:
        """[D] predictions at the current state, in demon order."""
        return self.fast.prediction()

    def horde_state(self) -> HordeState:
        return self.fast.horde_state()

    @property
    def sensors(self) -> np.ndarray:
        return self.fast.buf.sensors.copy()
