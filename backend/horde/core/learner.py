"""`Learner`: the one interface of a Horde learning from any source (grid, Gymnasium, stream, log), over the engine.

* `observe(sensors)`: an episode starts (or a stream begins) at a state with these sensors: traces restart;
* `learn(sensors_tp1, actions, b_probs, terminated, truncated)`: the transitions (s_t, a_t) -> s_{t+1},
  s_{t+1} -> s_{t+2}, ... one per row, with b(a_t | s_t) of each action taken; only the last row may end an
  episode, after which the caller observes the next episode's first state;
* `readout()`: what a run records every step or so, in O(D) (`Readout`);
* `state()` and `load(state)`: everything that changes, out and back in (`LearnerState`).

The grid world's `Simulation` steps its world inside the compiled loop (`Engine.run`) and shares the rest
of this interface (`Source`, `horde.core.source`); the Gymnasium agent, stream runs and recorded logs feed
`learn`. The learning step is the grid loop's own (`engine.step.learn`): the same question programs,
feature coding, kernels, divergence and metrics. Features must read sensors (or be constant): there is no
grid position.

Divergence, one rule for every source: a demon whose TD error, prediction, action values or any weight is
non-finite or beyond MAX_MAGNITUDE is marked diverged and frozen. The compiled step checks the TD errors,
predictions and action values at every step; every weight is scanned (`diverged_weights`) once every
`scan_interval` steps of learning (a deterministic count, so that the same seed gives the same run).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from horde.core.engine.engine import AdaptiveState, Engine
from horde.core.engine.layout import MAX_MAGNITUDE, Given
from horde.core.horde import Horde, HordeState
from horde.core.world import World
from horde.spec import BehaviourSpec

SCAN_WEIGHTS_PER_STEP = 10_000  # the weight scan's cost spread over the steps between two scans, at most
MIN_SCAN_INTERVAL = 1_000  # steps


class ExternalRecordError(ValueError):
    """A transition the engine cannot learn from (the message names the field: sensors, action, b_prob)."""


class Readout(NamedTuple):
    """Per-demon numbers of the agent's state, in demon order (copies)."""

    prediction: np.ndarray  # [D]
    cumulant: np.ndarray  # [D] the last cumulant
    delta: np.ndarray  # [D] the last TD error
    rupee: np.ndarray  # [D]
    ude: np.ndarray  # [D]
    diverged: np.ndarray  # [D] bool


class LearnerState(NamedTuple):
    """Everything a learner's demons keep: the Horde's state and what the learners beyond the gradient family
    add (`AdaptiveState`)."""

    horde: HordeState
    adaptive: AdaptiveState


def diverged_weights(horde: Horde, state: HordeState) -> np.ndarray:
    """[D] bool: demons whose prediction or any weight is non-finite or beyond MAX_MAGNITUDE."""
    out = ~(np.abs(state.prediction) <= MAX_MAGNITUDE)  # [D]; NaN compares False, so it counts
    per_block = [
        np.maximum(np.abs(theta).max(axis=0, initial=0.0), np.abs(w).max(axis=0, initial=0.0))  # [Db]; NaN propagates
        for theta, w in zip(state.theta, state.w, strict=True)
    ]
    if per_block:
        out[horde.slot_demon] |= ~(np.concatenate(per_block) <= MAX_MAGNITUDE)
    return out


class Learner:
    """A compiled Horde that learns (see the module).

    Args:
        horde: the compiled demons; its spec's world names the sensors.
        world: the grid world, when the caller steps it in the compiled loop (`Simulation`); None for a
            world fed from outside.
    """

    def __init__(self, horde: Horde, world: World | None = None) -> None:
        self.horde = horde
        self.engine = Engine(horde, world)
        self.sensor_names = list(horde.plan.sensors)
        self.num_sensors = len(self.sensor_names)
        self.num_actions = horde.num_actions
        column = {name: i for i, name in enumerate(self.sensor_names)}
        rules = []
        for c, demon in enumerate(horde.class_demon):
            policy = horde.demons[int(demon)].policy
            if policy.kind == "sign" and policy.sensor is not None and policy.actions is not None:
                rules.append([c, column[policy.sensor], policy.actions[0], policy.actions[1], policy.epsilon])
        self._rules = np.array(rules, dtype=float).reshape(-1, 5)  # [R, 5] (see engine.step.apply_rules)
        self.with_metrics = True
        self.steps = 0
        self.episodes = 0
        self.scan_interval = max(MIN_SCAN_INTERVAL, int(horde.block_rows @ [b.size for b in horde.blocks])
                                 // SCAN_WEIGHTS_PER_STEP if horde.blocks else 0)  # fmt: skip
        self._unscanned = 0  # steps learned since the last weight scan
        self.engine.set_learning(None)

    # ------------------------------------------------------------------------------------------
    # Learning

    def set_learning(self, learning: np.ndarray | None) -> None:
        """Which demons learn ([D] bool, default all); diverged demons stay frozen."""
        self.engine.set_learning(learning)

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
        self.engine.observe(self._sensor_rows(sensors)[0], self._rules)

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
        self.engine.learn_given(Given(rows, acts, probs, ends, self._rules, kept), self.with_metrics)
        self.steps += len(rows)
        if terminated or truncated:
            self.episodes += 1
        self.learned(len(rows))
        if not keep_predictions:
            return None
        out = np.empty_like(kept)
        out[:, self.horde.slot_demon] = kept
        return out

    def learned(self, steps: int) -> None:
        """Count `steps` steps learned (by `learn`, or by the grid world's loop); scan every weight for
        divergence once `scan_interval` of them have passed since the last scan (see the module)."""
        self._unscanned += steps
        if self._unscanned >= self.scan_interval:
            self._unscanned = 0
            self.scan_weights()

    def scan_weights(self) -> np.ndarray:
        """Freeze the demons whose weights (or prediction) went beyond MAX_MAGNITUDE or non-finite; returns [D]
        bool, the demons frozen now."""
        state = self.engine.horde_state()
        beyond = diverged_weights(self.horde, state) & ~state.diverged
        if beyond.any():
            self.engine.freeze(self.horde.demon_slot[np.flatnonzero(beyond)])
        return beyond

    # ------------------------------------------------------------------------------------------
    # Reading out, state in and out

    def readout(self) -> Readout:
        """What the run layer records every step or so, in O(D) (no weights are copied)."""
        engine = self.engine
        return Readout(
            prediction=engine.prediction(),
            cumulant=engine.per_demon(engine.t.dem.cumulant),
            delta=engine.per_demon(engine.t.dem.delta),
            rupee=engine.rupee(),
            ude=engine.ude(),
            diverged=engine.per_demon(engine.t.dem.diverged),
        )

    def state(self) -> LearnerState:
        """Copies of everything the demons keep."""
        return LearnerState(self.engine.horde_state(), self.engine.adaptive_state())

    def load(self, state: LearnerState, sensors: np.ndarray | None = None) -> None:
        """Put a `state()` of a learner of the same spec back; `sensors`: what they read where it stands."""
        self.engine.load(state.horde)
        self.engine.load_adaptive_state(state.adaptive)
        if sensors is not None:
            self.engine.t.agent.sensors[:] = self._sensor_rows(sensors)[0]

    def horde_state(self) -> HordeState:
        return self.engine.horde_state()

    def q(self) -> np.ndarray:
        """[D, A] action values at the current state (state-value demons: column 0 holds the value)."""
        return self.engine.per_demon(self.engine.t.dem.q)

    def behaviour_probs(self, behaviour: BehaviourSpec | None = None) -> np.ndarray:
        """[A] b(. | s) at the current state."""
        return self.horde.behaviour_probs(self.q()[None], behaviour)[0]

    def prediction(self) -> np.ndarray:
        """[D] predictions at the current state, in demon order."""
        return self.engine.prediction()

    @property
    def sensors(self) -> np.ndarray:
        """[S] the sensors at the state the learner stands in (a copy)."""
        return self.engine.t.agent.sensors.copy()
