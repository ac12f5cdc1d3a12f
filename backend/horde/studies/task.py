"""One task of a study: one configuration learns from scratch once, measured at checkpoints.

A task is a pure function of (run spec, run number, measure): its generator is seeded from the spec's
seed and the run number, as a protocol's trial is, so the same task gives the same numbers in this
process, in a Ray worker on this machine or on another node. Measuring never touches the learning
generator (Monte-Carlo rollouts draw from their own), so the learning trajectory does not depend on how
many checkpoints are taken.

Measures per demon at every checkpoint (episode 0, before learning, and `checkpoints` evenly spaced
points up to the last episode):
- `error`: on a lattice world (no noise, a start point, no indicators, a question that does not read
  `steps`), the root-mean-square error of the prediction over every non-terminal lattice state against the
  exact answer under the demon's current target policy (`core.evaluate.exact`), as the GVF literature
  reports; elsewhere the absolute error of the prediction at the start against the Monte-Carlo truth.
- `scale`: the size of the truth it is measured against (the root-mean-square of the exact answers, or
  the Monte-Carlo truth's magnitude), so errors of questions on different scales can be averaged as
  relative errors.
- `rupee`: RUPEE (White 2015), the online error measure a learner can compute without the truth.
And per checkpoint: the mean return of the episodes since the last checkpoint (the control return); after
training, for a control protocol (`protocol.test`), where its greedy test runs end (`counts`).
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from horde.core.evaluate import exact, lattice_points, monte_carlo
from horde.core.experiment import start_point
from horde.core.simulation import Simulation
from horde.core.world import World
from horde.spec import RunSpec, expr_sensors
from horde.studies.spec import MeasureSpec

TaskData = dict[str, Any]  # JSON-ready: see `run_task`


def checkpoint_episodes(episodes: int, checkpoints: int) -> list[int]:
    """Episode counts at which a run is measured: 0 and `checkpoints` evenly spaced points up to `episodes`."""
    marks = np.linspace(0, episodes, min(checkpoints, episodes) + 1).round().astype(int)
    return sorted({int(m) for m in marks})


def has_exact_answers(spec: RunSpec, demons: list[str]) -> bool:
    """Whether `core.evaluate.exact` covers these demons' questions in this world."""
    world = spec.grid
    if world.noise > 0 or len(world.start) != 2 or any(r.kind == "indicator" for r in world.regions):
        return False
    try:
        lattice_points(World(world))
    except ValueError:
        return False
    by_name = {d.name: d for d in spec.demons}
    for name in demons:
        demon = by_name[name]
        if any("steps" in expr_sensors(e) for e in (demon.cumulant, demon.outcome, demon.continuation)):
            return False
    return True


def _measure_error(
    sim: Simulation,
    name: str,
    at_start: float,
    exact_answers: bool,
    start: tuple[float, float],
    measure: MeasureSpec,
    truth_rng: np.random.Generator,
    row: dict[str, list[float]],
) -> None:
    """Append one checkpoint's error and scale of demon `name` (predicting `at_start` at the start) to its row.

    The error is the RMS error over the lattice against the exact answers where the world has them,
    else the error at the start against a Monte-Carlo truth (drawn from `truth_rng`).
    """
    horde, state = sim.horde, sim.horde_state
    if exact_answers:
        lattice = exact(horde, state, name)
        predicted = horde.forward(state, lattice.x, lattice.y).prediction[:, horde.index[name]]  # [N]
        row["error"].append(float(np.sqrt(np.mean((predicted - lattice.value) ** 2))))
        row["scale"].append(float(np.sqrt(np.mean(lattice.value**2))))
    else:
        truth = monte_carlo(horde, state, name, start, measure.rollouts, measure.cap, truth_rng)
        row["error"].append(abs(at_start - truth.mean))
        row["scale"].append(abs(truth.mean))


def _frozen(sim: Simulation, names: list[str]) -> list[str]:
    """The demons of `names` that the engine froze as diverged."""
    diverged = sim.horde_state.diverged  # [D]
    return [name for name in names if diverged[sim.horde.index[name]]]


def run_task(spec: RunSpec, run: int, measure: MeasureSpec) -> TaskData:
    """Train the spec's Horde once from scratch and measure it at checkpoints: on the grid (below), or on a
    Gymnasium world with known transitions, a chain or Baird's star (`chain_task.run_model_task`)."""
    if spec.world.kind == "gymnasium":
        from horde.studies.chain_task import run_model_task

        return run_model_task(spec, run, measure, checkpoint_episodes(spec.protocol.episodes, measure.checkpoints))
    return _grid_task(spec, run, measure)


def _grid_task(spec: RunSpec, run: int, measure: MeasureSpec) -> TaskData:
    """Train the spec's Horde on the grid once from scratch and measure it at checkpoints.

    Args:
        spec: the configuration's run spec (its protocol's `episodes` is the training length).
        run: the run number; the generator is `default_rng([spec.seed, run])`.
        measure: which demons, how many checkpoints, Monte-Carlo settings.

    Returns:
        {"episodes": [C], "truth": "exact" | "monte_carlo", "steps", "seconds", "cpu_seconds" (of this
         process), "returns": [C] (nan at 0),
         "demons": {name: {"error": [C], "scale": [C], "rupee": [C], "prediction": [C]}},
         "diverged": [measured demons the engine froze], "counts": {"positive", "negative", "none"} (control
         protocols only)}: C checkpoints.
    """
    began, began_cpu = time.perf_counter(), time.process_time()
    rng = np.random.default_rng([spec.seed, run])
    sim = Simulation(spec, rng)
    horde = sim.horde
    names = list(measure.demons) if measure.demons is not None else horde.prediction_demons()
    unknown = [n for n in names if n not in horde.index]
    if unknown:
        raise ValueError(f"measure.demons names unknown demons: {', '.join(unknown)}")
    exact_answers = has_exact_answers(spec, names)
    start = start_point(spec)
    marks = checkpoint_episodes(spec.protocol.episodes, measure.checkpoints)
    out: TaskData = {
        "episodes": marks,
        "truth": "exact" if exact_answers else "monte_carlo",
        "returns": [],
        "demons": {n: {"error": [], "scale": [], "rupee": [], "prediction": []} for n in names},
    }
    done = 0
    for checkpoint, mark in enumerate(marks):
        returns = []
        while done < mark:
            sim.run_episode()
            returns.append(sim.last_return)
            done += 1
        out["returns"].append(float(np.mean(returns)) if returns else float("nan"))
        at_start = sim.predictions_at(*start)
        rupee = horde.rupee(sim.horde_state)  # [D]
        for name in names:
            row = out["demons"][name]
            row["prediction"].append(at_start[name])
            row["rupee"].append(float(rupee[horde.index[name]]))
            truth_rng = np.random.default_rng([spec.seed, run, checkpoint, 1])
            _measure_error(sim, name, at_start[name], exact_answers, start, measure, truth_rng, row)
    out["steps"], out["diverged"] = sim.total_steps, _frozen(sim, names)
    test = spec.protocol.test
    if test is not None:  # a control protocol: where the test runs end after training, as horde run counts them
        learning = np.array([d.reset == "episode" for d in horde.demon_specs])
        tally = {1.0: 0, -1.0: 0, 0.0: 0}
        for _ in range(test.runs):
            sim.new_episode()
            tally[sim.run_episode(behaviour=test.behaviour, learning=learning).terminal_sign] += 1
        out["counts"] = {"positive": tally[1.0], "negative": tally[-1.0], "none": tally[0.0]}
    out["seconds"] = time.perf_counter() - began
    out["cpu_seconds"] = time.process_time() - began_cpu
    return out
