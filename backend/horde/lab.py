"""The textbook lab: Sutton & Barto's prediction experiments as a list a class runs from the dashboard's Lab tab.

Each experiment is a run (a scenario launched live) or a figure (a study file, run as `horde study` runs it),
with a sentence on what the class should see and the set-up a student may change before running it again:
`alpha`, `lambda`, basis `order` (each the field paths it sets), and a figure's `runs` per configuration.
`setup_run` and `setup_study` apply a set-up: a run's paths are set in the scenario's spec; a study's set the
values of the axis of that path (a list of numbers: "0.1, 0.3"), or add an axis of one value. Every value is
checked by the field's own validation: a problem is a `SpecError` at `setup.<name>` (a 422 naming the field).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from pydantic import ValidationError

from horde.runs.errors import FieldProblem, SpecError
from horde.scenarios import find_scenario
from horde.spec import RunSpec
from horde.studies.files import load_study_file, study_dir
from horde.studies.spec import MAX_RUNS, AxisSpec, StudySpec, apply, expand

SETUP_NAMES = ("alpha", "lambda", "order", "runs")
MAX_SETUP_VALUES = 16


@dataclass(frozen=True)
class Setting:
    """One thing a student may change: its name, the field paths it sets, and its value as shipped."""

    name: Literal["alpha", "lambda", "order", "runs"]
    paths: tuple[str, ...]
    value: str  # as shown and typed: "0.1" for a run, "0.05, 0.1, 0.2" for a study's axis


@dataclass(frozen=True)
class Experiment:
    id: str
    title: str
    kind: Literal["run", "study"]
    source: str  # the scenario's or the study file's name
    see: str  # one sentence: what the class should see
    setup: tuple[Setting, ...]


EXPERIMENTS: tuple[Experiment, ...] = (
    Experiment("walk-19", "19-state random walk, live (example 7.1)", "run", "random-walk-19",
               "Both learners' values climb from 0 toward the straight line from -0.9 to +0.9, the truth drawn beside "
               "them; with a larger alpha they get there sooner but keep shaking.",
               (Setting("alpha", ("learning.alpha",), "0.002"), Setting("lambda", ("learning.lambda",), "0.8"))),
    Experiment("boyan", "Boyan's chain, live (Sutton et al. 2009)", "run", "boyan-chain",
               "Six learners fall from 0 toward the line -2 s; TD and TDRC arrive first, the gradient learners lag, "
               "the original GTD (gtd1) last.",
               (Setting("alpha", ("learning.alpha",), "0.1"),)),
    Experiment("walk-1000", "1000-state random walk, live (example 9.1)", "run", "random-walk-1000",
               "State aggregation draws a staircase, the Fourier basis a smooth curve, the polynomial of order 1 a "
               "line; all bend toward the S-shaped truth.",
               (Setting("alpha", ("learning.alpha",), "0.002"),
                Setting("order", ("demons.fourier.features.order",), "5"))),
    Experiment("fig-12-3", "Figure 12.3: TD(lambda), error against alpha", "study", "fig-12-3-td-lambda",
               "Intermediate lambda reaches the lowest error at its best alpha; large lambda blows up at large alpha.",
               (Setting("alpha", ("learning.alpha",), "0.1, 0.3, 0.6, 1.0"),
                Setting("lambda", ("learning.lambda",), "0.0, 0.4, 0.8, 1.0"))),
    Experiment("fig-12-8", "Figure 12.8: true online TD(lambda)", "study", "fig-12-8-true-online",
               "Beside figure 12.3: about as good at small alpha, far better where TD(lambda) blows up.",
               (Setting("alpha", ("learning.alpha",), "0.1, 0.3, 0.6, 1.0"),
                Setting("lambda", ("learning.lambda",), "0.0, 0.4, 0.8, 1.0"))),
    Experiment("fig-9-5", "Figure 9.5: Fourier against polynomial bases", "study", "fig-9-5-bases",
               "At every order the Fourier basis' error falls far below the polynomial basis' of the same order.",
               (Setting("order", ("features.order",), "5, 10"),)),
    Experiment("fig-9-2", "Figure 9.2: TD(0) with state aggregation", "study", "fig-9-2-td-aggregation",
               "A staircase of ten steps, each near its group's true values, the outer ones pulled inward.",
               (Setting("alpha", ("learning.alpha",), "0.01"),)),
    Experiment("fig-9-1", "Figure 9.1: gradient Monte Carlo with state aggregation", "study",
               "fig-9-1-mc-aggregation",
               "A staircase whose steps follow the truth's mean over each group, weighted by how often it is visited.",
               (Setting("alpha", ("learning.alpha",), "0.0005"),)),
    Experiment("fig-11-5", "Figures 11.5 and 11.6: Baird's counterexample", "study", "fig-11-5-baird",
               "TD's error grows without bound; TDC's falls; emphatic TD's rises, then turns back down.",
               (Setting("alpha", ("demons.v.alpha",), "0.0003, 0.001, 0.003, 0.01"),)),
    Experiment("boyan-learners", "Boyan's chain: TD, GTD, GTD2, TDC, TDRC", "study", "boyan-chain-learners",
               "Every learner's error falls; TD and TDRC fastest, then TDC, GTD2, and the original GTD slowest.",
               (Setting("alpha", ("learning.alpha",), "0.1"),)),
)  # fmt: skip


def experiment(experiment_id: str) -> Experiment:
    """Raises: KeyError: no such experiment."""
    for entry in EXPERIMENTS:
        if entry.id == experiment_id:
            return entry
    raise KeyError(experiment_id)


def _numbers(name: str, text: str, many: bool) -> list[float | int]:  # order and runs are whole numbers
    """The numbers a set-up field holds ("0.1" or "0.1, 0.3"). Raises: SpecError at setup.<name>."""
    parts = [p.strip() for p in text.split(",") if p.strip()]
    if not parts or (not many and len(parts) > 1) or len(parts) > MAX_SETUP_VALUES:
        want = f"1 to {MAX_SETUP_VALUES} numbers separated by commas" if many else "one number"
        raise SpecError.at(("setup", name), f"{name}: give {want}, not {text!r}")
    out: list[float | int] = []
    for part in parts:
        try:
            out.append(int(part) if name in ("order", "runs") else float(part))
        except ValueError:
            raise SpecError.at(("setup", name), f"{name}: {part!r} is not a number") from None
    return out


def _check_names(entry: Experiment, setup: dict[str, str]) -> None:
    known = {s.name for s in entry.setup} | ({"runs"} if entry.kind == "study" else set())
    for name in setup:
        if name not in known:
            raise SpecError.at(("setup", name), f"{entry.id} takes no {name!r} (it takes: {', '.join(sorted(known))})")


def setup_run(experiment_id: str, setup: dict[str, str]) -> RunSpec:
    """The run spec of a run experiment with the set-up applied. Raises: SpecError at setup.<name>; KeyError."""
    entry = experiment(experiment_id)
    _check_names(entry, setup)
    data = find_scenario(entry.source).model_dump(by_alias=True)
    for setting in entry.setup:
        if setting.name not in setup:
            continue
        value = _numbers(setting.name, setup[setting.name], many=False)[0]
        try:
            data = apply(data, dict.fromkeys(setting.paths, value))
            RunSpec.model_validate(data)
        except (ValidationError, ValueError) as exc:
            message = exc.errors()[0]["msg"] if isinstance(exc, ValidationError) else str(exc)
            raise SpecError.at(("setup", setting.name), f"{setting.name} = {value}: {message}") from None
    return RunSpec.model_validate(data)


def setup_study(experiment_id: str, setup: dict[str, str]) -> tuple[StudySpec, RunSpec]:
    """The study (its base inlined) of a figure with the set-up applied. Raises: SpecError at setup.<name>;
    KeyError."""
    entry = experiment(experiment_id)
    _check_names(entry, setup)
    study, base, _ = load_study_file(study_dir() / f"{entry.source}.toml")
    axes = list(study.axes)
    for setting in entry.setup:
        if setting.name not in setup:
            continue
        values = _numbers(setting.name, setup[setting.name], many=True)
        for path in setting.paths:
            found = next((i for i, a in enumerate(axes) if a.path == path), None)
            axis = AxisSpec(path=path, values=list(values))
            if found is None:
                axes.append(axis)
            else:
                axes[found] = axis
    runs = study.runs
    if "runs" in setup:
        runs = int(_numbers("runs", setup["runs"], many=False)[0])
        if not 1 <= runs <= MAX_RUNS:
            raise SpecError.at(("setup", "runs"), f"runs: give 1 to {MAX_RUNS}, not {runs}")
    edited = study.model_copy(update={"axes": axes, "base": base, "scenario": None, "runs": runs})
    try:
        expand(edited, base)
    except SpecError as exc:
        problems = [FieldProblem(("setup", _name_of(entry, axes, p.loc)), p.msg) for p in exc.problems]
        raise SpecError(problems) from None
    return edited, base


def _name_of(entry: Experiment, axes: list[AxisSpec], loc: tuple[str | int, ...]) -> str:
    """The set-up field an axis problem belongs to (its first, when the problem names no axis)."""
    if len(loc) >= 2 and loc[0] == "axes" and isinstance(loc[1], int) and loc[1] < len(axes):
        path = axes[loc[1]].path
        for setting in entry.setup:
            if path in setting.paths:
                return setting.name
    return entry.setup[0].name if entry.setup else "setup"
