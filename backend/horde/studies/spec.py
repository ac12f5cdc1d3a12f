"""The spec of a study: a base RunSpec, axes over its fields, how many runs each, what to measure.

A study varies fields of a base scenario (or an inline RunSpec) by path, as a full grid or as a random
sample of the grid, and gives every configuration `runs` independent runs. Each configuration x run is
one task. `expand` turns a study into its configurations, and checks every axis before any task starts:
an unknown path, a value that fails the field's own validation, or more configurations or tasks than
the bounds below is a `SpecError` located at the axis (`axes.<i>.path` or `axes.<i>.values.<j>`), whose
message names the axis' path.

Paths are dotted field names of the RunSpec as written in a scenario file (`learning.alpha`,
`learning.lambda`, `world.slip`, `features.tiles`, `seed`). A list of named things (`demons`, `world.regions`)
takes a name, `*` (every element) or an index: `demons.*.learner`, `demons.goal.alpha`, `demons.0.lambda`.
"""

from __future__ import annotations

import copy
import itertools
import math
import random
from dataclasses import dataclass
from typing import Annotated, Any, Literal

from pydantic import Field, ValidationError, model_validator

from horde.runs.errors import FieldProblem, SpecError
from horde.spec import Model, Name, RunSpec

MAX_AXES = 6
MAX_VALUES = 64  # per axis
MAX_CONFIGURATIONS = 1_000  # after the grid (or the random sample) is taken
MAX_RUNS = 100  # per configuration
MAX_TASKS = 20_000  # configurations x runs
MAX_CHECKPOINTS = 200

AxisValue = float | int | str | bool
Path = Annotated[str, Field(min_length=1, max_length=200, pattern=r"^[A-Za-z0-9_*.:-]+$")]


class AxisSpec(Model):
    """One field to vary and the values it takes."""

    path: Path = Field(description="a dotted field path of the run spec, e.g. learning.alpha or demons.*.learner")
    values: list[AxisValue] = Field(min_length=1, max_length=MAX_VALUES)


class SampleSpec(Model):
    """Every configuration of the grid, or `size` of them drawn at random (without repeats, seeded)."""

    kind: Literal["grid", "random"] = "grid"
    size: int | None = Field(default=None, ge=1, le=MAX_CONFIGURATIONS, description="random: how many")
    seed: int = Field(default=0, ge=0, le=2**32 - 1)

    @model_validator(mode="after")
    def _size(self) -> SampleSpec:
        if self.kind == "random" and self.size is None:
            raise ValueError("a random sample needs a size")
        if self.kind == "grid" and self.size is not None:
            raise ValueError("a grid takes every configuration: size belongs to random samples")
        return self


class MeasureSpec(Model):
    """What each run measures, at `checkpoints` evenly spaced points of its training (and before it)."""

    episodes: int | None = Field(
        default=None, ge=1, le=1_000_000, description="training episodes per run (default: the base protocol's)"
    )
    checkpoints: int = Field(default=10, ge=1, le=MAX_CHECKPOINTS)
    demons: list[Name] | None = Field(default=None, description="which demons (default: every prediction demon)")
    rollouts: int = Field(
        default=300, ge=1, le=100_000, description="Monte-Carlo rollouts per checkpoint where no exact answer exists"
    )
    cap: int = Field(default=10_000, ge=1, le=1_000_000, description="rollout length limit")
    weighting: Literal["on-policy", "uniform"] = Field(
        default="on-policy",
        description="worlds with known transitions (the chains, Baird's star): the RMS error over the states "
        "weighted by the behaviour's distribution (the book's VE) or every state alike (its 19-state walk figures)",
    )


class StudySpec(Model):
    """A parameter study (DESIGN: studies/)."""

    name: Name | None = None
    description: str = Field(default="", max_length=2000)
    caption: str = Field(
        default="", max_length=2000, description="written under every figure: which figure, the set-up, what to see"
    )
    scenario: Name | None = Field(default=None, description="the base scenario's name (or give `base`)")
    base: RunSpec | None = Field(default=None, description="the base run spec (or name a `scenario`)")
    axes: list[AxisSpec] = Field(
        default_factory=list, max_length=MAX_AXES, description="none: one configuration, the base, over `runs`"
    )
    sample: SampleSpec = Field(default_factory=SampleSpec)
    runs: int = Field(default=5, ge=1, le=MAX_RUNS, description="independent runs per configuration")
    measure: MeasureSpec = Field(default_factory=MeasureSpec)

    @model_validator(mode="after")
    def _one_base(self) -> StudySpec:
        if (self.scenario is None) == (self.base is None):
            raise ValueError("a study names a scenario or gives a base run spec (exactly one of them)")
        paths = [a.path for a in self.axes]
        repeated = sorted({p for p in paths if paths.count(p) > 1})
        if repeated:
            raise ValueError(f"each axis varies a different path: {', '.join(repeated)} repeats")
        return self


@dataclass(frozen=True)
class Configuration:
    """One point of the study: its axis values and the run spec they make."""

    index: int
    axes: dict[str, AxisValue]
    spec: RunSpec


def _segments(path: str) -> list[str]:
    return path.split(".")


def _targets(
    data: Any, segments: list[str], trail: str = "", root: dict[str, Any] | None = None
) -> list[tuple[dict[str, Any], str]]:
    """The (parent dict, key) pairs a path names in a dumped spec; ValueError names the unknown part.

    A demon without its own `features` uses the run's: a path into them starts from a copy of the run's.
    """
    root = data if root is None else root
    if not segments:
        raise ValueError("an empty path")
    head, rest = segments[0], segments[1:]
    here = f"{trail}.{head}" if trail else head
    if isinstance(data, list):
        if head == "*":
            chosen = list(data)
        elif head.isdigit():
            if int(head) >= len(data):
                raise ValueError(f"{here}: index {head} past the list's {len(data)} elements")
            chosen = [data[int(head)]]
        else:
            chosen = [item for item in data if isinstance(item, dict) and item.get("name") == head]
            if not chosen:
                names = [str(item.get("name")) for item in data if isinstance(item, dict)]
                raise ValueError(f"{here}: no element named {head!r} (there are: {', '.join(names) or 'none'})")
        if not rest:
            raise ValueError(f"{here}: names a whole list element; add the field to vary")
        return [t for item in chosen for t in _targets(item, rest, here, root)]
    if not isinstance(data, dict):
        raise ValueError(f"{trail}: is a value, not a group of fields")
    if head not in data:
        raise ValueError(f"{here}: no such field (known here: {', '.join(sorted(data))})")
    if not rest:
        return [(data, head)]
    if data[head] is None:  # an optional group left out: a demon's own features start as the run's
        data[head] = copy.deepcopy(root.get(head)) if isinstance(root.get(head), dict) else {}
    return _targets(data[head], rest, here, root)


def _dump(spec: RunSpec) -> dict[str, Any]:
    return spec.model_dump(by_alias=True, exclude_none=False)


def _known_paths(data: dict[str, Any], path: str) -> None:
    """Check that a path exists in the spec with every optional group filled in with its defaults."""
    _targets(copy.deepcopy(data), _segments(path))


def apply(spec_data: dict[str, Any], values: dict[str, AxisValue]) -> dict[str, Any]:
    """A copy of a dumped spec with each path set to its value."""
    data = copy.deepcopy(spec_data)
    for path, value in values.items():
        for parent, key in _targets(data, _segments(path)):
            parent[key] = value
    return data


def _fmt(value: AxisValue) -> str:
    return repr(value) if isinstance(value, str) else f"{value}"


def _validate(data: dict[str, Any]) -> RunSpec:
    spec = RunSpec.model_validate(data)
    if spec.protocol.episodes == 0:
        raise ValueError("the base protocol has 0 episodes: set measure.episodes")
    return spec


def grid_points(study: StudySpec) -> list[tuple[int, ...]]:
    """Indices into each axis' values: the whole grid, or its seeded random sample (in grid order)."""
    sizes = [len(a.values) for a in study.axes]
    total = math.prod(sizes)
    if study.sample.kind == "grid":
        if total > MAX_CONFIGURATIONS:
            raise SpecError.at(
                ("axes",),
                f"the grid of {' x '.join(a.path for a in study.axes)} has {total} configurations, more than "
                f"{MAX_CONFIGURATIONS}; take fewer values or a random sample",
            )
        return list(itertools.product(*(range(n) for n in sizes)))
    size = study.sample.size or 0
    if size > total:
        raise SpecError.at(("sample", "size"), f"a sample of {size} from a grid of only {total} configurations")
    chosen = sorted(random.Random(study.sample.seed).sample(range(total), size))
    points = []
    for flat in chosen:
        point = []
        for n in reversed(sizes):
            flat, i = divmod(flat, n)
            point.append(i)
        points.append(tuple(reversed(point)))
    return points


def expand(study: StudySpec, base: RunSpec) -> list[Configuration]:
    """The study's configurations, every one validated, before any task starts.

    Args:
        study: the study.
        base: its base run spec (the named scenario, or `study.base`).

    Raises:
        SpecError: located at the axis (`axes.<i>.path`, `axes.<i>.values.<j>`), `sample.size`, `runs` or
            `measure.demons.<j>`.
    """
    if study.measure.episodes is not None:
        base = base.model_copy(
            update={"protocol": base.protocol.model_copy(update={"episodes": study.measure.episodes})}
        )
    data = _dump(base)
    problems: list[FieldProblem] = []
    names = {d.name for d in base.demons}
    for j, name in enumerate(study.measure.demons or []):
        if name not in names:
            known = ", ".join(sorted(names)) or "none"
            problems.append(FieldProblem(("measure", "demons", j), f"no demon {name!r} to measure (known: {known})"))
    for i, axis in enumerate(study.axes):
        try:
            _known_paths(data, axis.path)
        except ValueError as exc:
            problems.append(FieldProblem(("axes", i, "path"), f"axis {axis.path}: unknown path: {exc}"))
            continue
        for j, value in enumerate(axis.values):
            try:
                _validate(apply(data, {axis.path: value}))
            except ValidationError as exc:
                first = exc.errors()[0]
                field = ".".join(str(p) for p in first["loc"])
                problems.append(
                    FieldProblem(("axes", i, "values", j), f"axis {axis.path} = {_fmt(value)}: {field}: {first['msg']}")
                )
            except ValueError as exc:
                problems.append(FieldProblem(("axes", i, "values", j), f"axis {axis.path} = {_fmt(value)}: {exc}"))
    if problems:
        raise SpecError(problems)
    points = grid_points(study)
    if len(points) * study.runs > MAX_TASKS:
        raise SpecError.at(
            ("runs",),
            f"{len(points)} configurations x {study.runs} runs = {len(points) * study.runs} tasks, "
            f"more than {MAX_TASKS}",
        )
    configurations = []
    for index, point in enumerate(points):
        values = {axis.path: axis.values[i] for axis, i in zip(study.axes, point, strict=True)}
        try:
            spec = _validate(apply(data, values))
        except (ValidationError, ValueError) as exc:
            message = exc.errors()[0]["msg"] if isinstance(exc, ValidationError) else str(exc)
            named = ", ".join(f"{p} = {_fmt(v)}" for p, v in values.items())
            raise SpecError.at(("axes",), f"the configuration {named} does not validate: {message}") from None
        configurations.append(Configuration(index, values, spec))
    return configurations


def label(axes: dict[str, AxisValue]) -> str:
    """A short name of a configuration: `alpha=0.1 lambda=0.9 learner='td'` (the last part of each path)."""
    return " ".join(f"{path.split('.')[-1]}={_fmt(v)}" for path, v in axes.items())


def study_warnings(configurations: list[Configuration]) -> list[str]:
    """What the results of these configurations will not show on their own, one sentence each.

    Today one: GTD(lambda) with alpha_w = 0 is TD(lambda). Its correction weights w start at 0 and never move,
    so the correction term gamma (1 - lambda) (w . e) phi' is 0 and every update equals TD's: a learner axis
    over td and gtd then gives identical rows.
    """
    same_as_td = [
        c.index
        for c in configurations
        if any(
            d.learner == "gtd" and (d.alpha_w if d.alpha_w is not None else c.spec.learning.alpha_w) == 0
            for d in c.spec.demons
        )
    ]
    if not same_as_td:
        return []
    shown = ", ".join(map(str, same_as_td[:10])) + (", ..." if len(same_as_td) > 10 else "")
    return [
        f"gtd with alpha_w = 0 learns exactly as td (its correction weights stay 0), so td and gtd give identical "
        f"results in configuration{'s' if len(same_as_td) > 1 else ''} {shown}; give alpha_w a value above 0 to "
        "compare them"
    ]
