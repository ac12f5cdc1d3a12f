"""The one engine fed from outside: learn from transitions whose sensors someone else observed.

The grid world is simulated inside the compiled loop (`fast._run`). Every other world kind (a Gymnasium
environment stepped in Python, a live stream of pushed records, a recorded log read at full speed) feeds
the same compiled Horde through this one input path:

* `observe(sensors)`: an episode starts at a state with these sensors (traces restart, DESIGN section 5);
* `learn(sensors_tp1, actions, b_probs, terminated, truncated)`: the transitions
  (s_t, a_t) -> s_{t+1}, s_{t+1} -> s_{t+2}, ... one per row, with b(a_t | s_t) of each action taken.
  Only the last row may end an episode; then the caller observes the next episode's first state.

The learning step is the grid loop's own: `fast._run` takes its transitions from the given rows
(`fast.Given`) in place of the world's moves, with the same stage-by-stage question programs, feature
coding, block kernels (`scale_fast._step`), adaptive learners, divergence freeze and RUPEE/UDE metrics.
Features must be tiled over sensors (or constant): there is no grid position.
Tests check that feeding the grid world's own transitions here gives the grid loop's numbers exactly.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from horde.core.adaptive_kernels import online_reset
from horde.core.fast import FOREVER, FastLoop, Given, _apply_rules, _observe, _run
from horde.core.horde import Horde, HordeState
from horde.core.world import World
from horde.spec import BehaviourSpec, WorldSpec


class ExternalRecordError(ValueError):
    """A transition the engine cannot learn from (the message names the field: sensors, action, b_prob)."""


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
        na = self.num_actions  # the loop's behaviour and generator, unused on given rows:
        self._no_behaviour = (np.zeros(2, np.int64), np.zeros(2), np.full(na, 1.0 / na))
        self._rng = np.random.default_rng(0)
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
        acts = np.ascontiguousarray(np.asarray(actions, dtype=np.int64).reshape(-1))
        probs = np.ascontiguousarray(np.asarray(b_probs, dtype=float).reshape(-1))
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
        given = Given(rows, acts, probs, ends, self._rules, kept)
        _run(fast.net, fast.buf, self._rng, len(rows), FOREVER, *self._no_behaviour, self.with_metrics, fast.onl, 1,
             given)  # fmt: skip
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
