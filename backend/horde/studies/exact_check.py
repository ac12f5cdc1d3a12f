"""Every demon of a lattice scenario against its exact answer at the start, after the scenario's protocol.

The issue's "What must hold 1": on every shipped lattice scenario (a grid world whose exact answers a
linear solve gives: `core.evaluate.exact`), with `[learning] step_size = "autostep"` and no other tuning,
every demon's prediction at the start is within 5 % of the exact answer (0.05 for a probability). The
exact answer is the one under the demon's target policy as it stands after learning (for `{of = base}`
demons and the control demon itself, the base demon's learned policy), so it is solved per trial.

An adaptive step size applies to the demons whose learner defines it (`spec.demon_step_size`); the others
keep their constant step sizes, and the table says which mode each demon ran with.

`python -m horde.studies.exact_check [--step-size autostep] [--trials N] [--out docs/autostep-exact.md]`
runs every shipped lattice scenario and writes the table (docs/autostep-exact.md).
"""

from __future__ import annotations

import argparse
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from horde.core.evaluate import exact
from horde.core.experiment import learn, start_point
from horde.scenarios import list_scenarios, load_scenario
from horde.spec import RunSpec, StepSize, demon_step_size
from horde.studies.task import has_exact_answers

RELATIVE_TOLERANCE = 0.05  # of the exact answer
PROBABILITY_TOLERANCE = 0.05  # absolute, for questions whose answers are probabilities


@dataclass(frozen=True)
class DemonCheck:
    """One demon of one scenario, over the protocol's trials."""

    scenario: str
    demon: str
    learner: str
    step_size: str  # the mode it ran with
    probability: bool  # its answers lie in [0, 1] with no cumulant: judged by the absolute error
    exact: np.ndarray  # [trials] exact answer at the start under its learned target policy
    prediction: np.ndarray  # [trials]

    @property
    def errors(self) -> np.ndarray:
        """[trials] absolute error (probabilities) or error relative to the exact answer."""
        gap = np.abs(self.prediction - self.exact)
        return gap if self.probability else gap / np.abs(self.exact)

    @property
    def tolerance(self) -> float:
        return PROBABILITY_TOLERANCE if self.probability else RELATIVE_TOLERANCE

    @property
    def holds(self) -> bool:
        """Within tolerance in every trial."""
        return bool(np.all(self.errors <= self.tolerance))


def lattice_scenarios(directory: Path | None = None) -> list[tuple[str, RunSpec]]:
    """The shipped grid scenarios whose every demon has an exact answer, by name."""
    out = []
    for info in list_scenarios(directory):
        spec = load_scenario(info.path)
        if spec.world.kind == "grid" and has_exact_answers(spec, [d.name for d in spec.demons]):
            out.append((info.name, spec))
    return out


def with_step_size(spec: RunSpec, step_size: StepSize) -> RunSpec:
    """The spec with `[learning] step_size` set and nothing else changed (validated again)."""
    body = spec.model_dump(by_alias=True)
    body["learning"]["step_size"] = step_size
    return RunSpec.model_validate(body)


def check(name: str, spec: RunSpec, trials: int | None = None) -> list[DemonCheck]:
    """Learn each trial as the protocol does, then compare every demon with its exact answer at the start."""
    count = spec.protocol.trials if trials is None else trials
    start = start_point(spec)
    exact_values: dict[str, list[float]] = {d.name: [] for d in spec.demons}
    predictions: dict[str, list[float]] = {d.name: [] for d in spec.demons}
    probability = {d.name: d.cumulant == 0 for d in spec.demons}
    for trial in range(count):
        sim, _, _ = learn(spec, trial)
        at_start = sim.predictions_at(*start)
        state = sim.horde_state
        for demon in spec.demons:
            lattice = exact(sim.horde, state, demon.name)
            here = int(np.argmin(np.hypot(lattice.x - start[0], lattice.y - start[1])))
            exact_values[demon.name].append(float(lattice.value[here]))
            predictions[demon.name].append(at_start[demon.name])
            inside = (lattice.value >= -1e-9) & (lattice.value <= 1 + 1e-9)
            probability[demon.name] = probability[demon.name] and bool(inside.all())
    return [
        DemonCheck(
            scenario=name,
            demon=d.name,
            learner=d.learner,
            step_size=demon_step_size(d, spec.learning)[0],
            probability=probability[d.name],
            exact=np.array(exact_values[d.name]),
            prediction=np.array(predictions[d.name]),
        )
        for d in spec.demons
    ]


def table(rows: list[DemonCheck]) -> str:
    """A markdown table: per demon the means over trials, the worst trial's error and whether it holds."""
    lines = [
        "| scenario | demon | learner | step size | exact (mean) | prediction (mean) | error (mean) | "
        "error (worst trial) | bound | holds |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        unit = "" if r.probability else " %"
        scale = 1.0 if r.probability else 100.0
        lines.append(
            f"| {r.scenario} | {r.demon} | {r.learner} | {r.step_size} | {r.exact.mean():.4g} | "
            f"{r.prediction.mean():.4g} | {scale * r.errors.mean():.3g}{unit} | {scale * r.errors.max():.3g}{unit} | "
            f"{scale * r.tolerance:g}{unit} | {'yes' if r.holds else '**no**'} |"
        )
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--step-size", default="autostep", choices=["constant", "autostep", "tidbd"])
    parser.add_argument("--trials", type=int, default=None, help="default: each scenario's protocol")
    parser.add_argument("--only", nargs="*", default=None, help="scenario names (default: every lattice one)")
    parser.add_argument("--out", type=Path, default=None, help="append the table to this markdown file")
    args = parser.parse_args()
    rows: list[DemonCheck] = []
    for name, spec in lattice_scenarios():
        if args.only and name not in args.only:
            continue
        began, cpu = time.perf_counter(), time.process_time()
        found = check(name, with_step_size(spec, args.step_size), args.trials)
        print(f"{name}: {time.perf_counter() - began:.0f} s wall, {time.process_time() - cpu:.0f} s CPU", flush=True)
        print(table(found), flush=True)
        rows += found
    if args.out is not None:
        with args.out.open("a") as out:
            out.write(table(rows) + "\n")


if __name__ == "__main__":
    main()
