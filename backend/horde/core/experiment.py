"""The protocol of the thesis: trials x episodes x max steps, evaluation, test runs.

Each trial learns from scratch with its own generator (seeded from the run seed and the trial
number), stops after `episodes` or earlier by the stopping rule, then reports each demon's prediction
at the start, its Monte-Carlo truth, and (for a control protocol) where its test runs ended.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from horde.core.engine.layout import FOREVER
from horde.core.evaluate import Truth, monte_carlo
from horde.core.simulation import Simulation
from horde.spec import Counts, RunSpec, StopRule

Progress = Callable[[int, int], None]  # (episodes done, episodes in all)
# Episodes a trial runs per call into the compiled loop (without a stopping rule): a call costs about
# 70 us of Python, a third of what an episode of Experiment 1 takes to learn (docs/performance.md).
EPISODES_PER_CALL = 100


@dataclass
class TrialResult:
    predictions: dict[str, float]
    truths: dict[str, Truth]
    counts: Counts | None
    episodes: int
    steps: int


@dataclass
class DemonResult:
    name: str
    prediction: float
    truth: float | None
    truth_stderr: float | None
    error: float | None
    thesis: float | None
    counts: Counts | None = None

    def as_dict(self) -> dict[str, object]:
        out: dict[str, object] = {
            "name": self.name,
            "prediction": self.prediction,
            "truth": self.truth,
            "truth_stderr": self.truth_stderr,
            "error": self.error,
            "thesis": self.thesis,
        }
        if self.counts is not None:
            out["counts"] = self.counts.model_dump()
        return out


@dataclass
class ProtocolResult:
    demons: list[DemonResult]
    trials: list[TrialResult]
    seconds: float
    steps: int
    thesis_counts: Counts | None = None
    rollout_cap: int = 0
    notes: list[str] = field(default_factory=list)

    @property
    def steps_per_second(self) -> float:
        return self.steps / self.seconds if self.seconds > 0 else math.nan


def start_point(spec: RunSpec) -> tuple[float, float]:
    """Where predictions are read and rollouts start: the start point, or the start rectangle's centre."""
    s = spec.grid.start
    return (s[0], s[1]) if len(s) == 2 else ((s[0] + s[2]) / 2, (s[1] + s[3]) / 2)


def stopping_rule(
    stop: StopRule | None, episodes: int, thetas: Callable[[], list[np.ndarray]], reference: list[np.ndarray]
) -> tuple[bool, list[np.ndarray]]:
    """The protocol's stopping rule after `episodes` episodes: (stop now?, the reference weights to keep).

    Every `stop.window` episodes the largest change of any weight since `reference` is compared with
    `stop.tolerance`: below it the trial stops; otherwise the current weights become the reference.
    `thetas` is called only then (copying every weight of a large Horde is not free).
    """
    if stop is None or episodes % stop.window != 0:
        return False, reference
    current = thetas()
    change = max((float(np.abs(new - old).max()) for new, old in zip(current, reference, strict=True)), default=0.0)
    if change < stop.tolerance:
        return True, reference
    return False, current


def learn(
    spec: RunSpec, trial: int, progress: Callable[[int], None] | None = None
) -> tuple[Simulation, np.random.Generator, int]:
    """One trial's learning from scratch: (the simulation, its generator, episodes learned)."""
    rng = np.random.default_rng([spec.seed, trial])
    sim = Simulation(spec, rng)
    sim.with_metrics = False  # RUPEE / UDE are for watching; the protocol reports against the truth
    reference = sim.thetas()
    episodes = 0
    protocol = spec.protocol
    stop = protocol.stop
    chunk = stop.window if stop is not None else EPISODES_PER_CALL  # the rule looks every `window` episodes
    while episodes < protocol.episodes:
        sim.run(FOREVER, min(chunk, protocol.episodes - episodes))  # as many run_episode calls, in one
        episodes = min(episodes + chunk, protocol.episodes)
        if progress:
            progress(episodes)
        stopped, reference = stopping_rule(stop, episodes, sim.thetas, reference)
        if stopped:
            break
    return sim, rng, episodes


def run_trial(spec: RunSpec, trial: int, progress: Callable[[int], None] | None = None) -> TrialResult:
    """Learn from scratch, then evaluate at the start point and run the test runs."""
    protocol = spec.protocol
    sim, rng, episodes = learn(spec, trial, progress)
    horde = sim.horde
    start = start_point(spec)
    predictions = sim.predictions_at(*start)
    evaluation = protocol.evaluation
    names = evaluation.demons if evaluation.demons is not None else horde.names
    truths: dict[str, Truth] = {}
    if evaluation.rollouts > 0:
        for name in names:
            truths[name] = monte_carlo(horde, sim.horde_state, name, start, evaluation.rollouts, evaluation.cap, rng)
    counts = None
    if protocol.test is not None:
        learning = np.array([d.reset == "episode" for d in horde.demon_specs])
        tally = {1.0: 0, -1.0: 0, 0.0: 0}
        for _ in range(protocol.test.runs):
            sim.new_episode()
            last = sim.run_episode(behaviour=protocol.test.behaviour, learning=learning)
            tally[last.terminal_sign] += 1
        counts = Counts(positive=tally[1.0], negative=tally[-1.0], none=tally[0.0])
    return TrialResult(predictions, truths, counts, episodes, sim.total_steps)


def run_protocol(spec: RunSpec, progress: Progress | None = None) -> ProtocolResult:
    """All trials of the spec's protocol, aggregated per demon (means over trials)."""
    protocol = spec.protocol
    total = protocol.trials * protocol.episodes
    began = time.perf_counter()
    trials: list[TrialResult] = []
    for trial in range(protocol.trials):
        done_before = trial * protocol.episodes

        def report(episodes: int, done_before: int = done_before) -> None:
            if progress:
                progress(done_before + episodes, total)

        trials.append(run_trial(spec, trial, report))
        if progress:
            progress((trial + 1) * protocol.episodes, total)
    return summarize(spec, trials, time.perf_counter() - began)


def summarize(spec: RunSpec, trials: list[TrialResult], seconds: float) -> ProtocolResult:
    """The protocol's result from its trials (however they were run)."""
    return ProtocolResult(
        demons=aggregate(spec, trials),
        trials=trials,
        seconds=seconds,
        steps=sum(t.steps for t in trials),
        thesis_counts=spec.thesis.counts,
        rollout_cap=spec.protocol.evaluation.cap,
    )


def aggregate(spec: RunSpec, trials: list[TrialResult]) -> list[DemonResult]:
    """Per demon: mean prediction and mean truth over trials; the error is their difference."""
    results = []
    test_demon = spec.protocol.test.behaviour.demon if spec.protocol.test else None
    for demon in spec.demons:
        name = demon.name
        prediction = float(np.mean([t.predictions[name] for t in trials]))
        truths = [t.truths[name] for t in trials if name in t.truths]
        truth = stderr = error = None
        if truths:
            truth = float(np.mean([t.mean for t in truths]))
            stderr = float(math.sqrt(sum(t.stderr**2 for t in truths)) / len(truths))
            error = prediction - truth
        counts = None
        if name == test_demon:
            counts = Counts(
                positive=sum(t.counts.positive for t in trials if t.counts),
                negative=sum(t.counts.negative for t in trials if t.counts),
                none=sum(t.counts.none for t in trials if t.counts),
            )
        results.append(DemonResult(name, prediction, truth, stderr, error, spec.thesis.predictions.get(name), counts))
    return results
