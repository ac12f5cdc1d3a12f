"""The data model of Horde Lab: worlds, features, questions, demons, runs.

Every model is frozen and forbids unknown keys, so a typo in a scenario file or an API request is a
422 naming the field instead of a silently ignored setting. Every size is bounded (DESIGN section 8,
security). The same models validate TOML scenario files and REST bodies.

Why one module of about 1150 lines: it is the whole data model, read top-down as a schema (world,
features, expressions, demons, protocol, run), and its cross-field checks (a demon's expression naming
a sensor the world defines, a family expanding into demons that name each other) need the classes
together; its functions are short. Moving whole classes out would be re-exported from here anyway.
"""

from __future__ import annotations

import heapq
import itertools
import math
import re
from collections.abc import Iterator
from functools import partial
from typing import Annotated, Any, Literal

from pydantic import (
    BaseModel,
    ConfigDict,
    Discriminator,
    Field,
    PrivateAttr,
    Tag,
    ValidationError,
    ValidationInfo,
    field_validator,
    model_validator,
)
from pydantic_core import InitErrorDetails, PydanticCustomError

ACTIONS: tuple[str, ...] = ("up", "down", "left", "right")

MAX_WORLD_SIZE = 1e6
# What a start rectangle whose every point lies in an obstacle or a terminal is told, by the spec (a 422 at
# `world.start`) and by both engines (horde.core.world.ImpossibleStartError) if an unvalidated spec reaches them.
IMPOSSIBLE_START = "the start rectangle has no cell outside obstacles and terminals"
MAX_REGIONS = 64
MAX_COLORS = 16
MAX_DEMONS = 10_000
MAX_FEATURES = 1_000_000
MAX_EXPR_NODES = 256
MAX_EXPR_DEPTH = 16  # expressions inside expressions, checked before pydantic validates them
MAX_STEPS = 1_000_000
MAX_EPISODES = 1_000_000
MAX_TRIALS = 1_000

NAME_MAX = 64
NAME_PATTERN = r"^[A-Za-z_][A-Za-z0-9_.-]*$"
NAME_RULE = f"1 to {NAME_MAX} letters, digits, '_', '.' or '-', the first a letter or '_'"
_NAME = re.compile(NAME_PATTERN)
Name = Annotated[str, Field(min_length=1, max_length=NAME_MAX, pattern=NAME_PATTERN)]
Finite = Annotated[float, Field(allow_inf_nan=False)]
Probability = Annotated[float, Field(ge=0.0, le=1.0, allow_inf_nan=False)]
PositiveSize = Annotated[float, Field(gt=0.0, le=MAX_WORLD_SIZE, allow_inf_nan=False)]
MIN_HZ = 0.01  # paced runs: one step every 100 s at the slowest
MAX_HZ = 10_000.0  # beyond this, run at full speed (hz = null)
Hz = Annotated[
    float,
    Field(
        ge=MIN_HZ,
        le=MAX_HZ,
        allow_inf_nan=False,
        description=f"steps per second, {MIN_HZ} to {MAX_HZ:g}; null: as fast as possible",
    ),
]


class Model(BaseModel):
    model_config = ConfigDict(frozen=True, extra="forbid", populate_by_name=True)


# ----------------------------------------------------------------------------------------------
# Expressions: cumulant, outcome, continuation (DESIGN section 4). Data, never eval.


class SensorExpr(Model):
    sensor: str = Field(min_length=1, max_length=80, description="a sensor name, e.g. in:goal")


class PredictionExpr(Model):
    prediction: Name = Field(description="another demon's current prediction")


class AddExpr(Model):
    add: list[Expr] = Field(min_length=1, max_length=32)


class MulExpr(Model):
    mul: list[Expr] = Field(min_length=1, max_length=32)


class MinExpr(Model):
    min: list[Expr] = Field(min_length=1, max_length=32)


class MaxExpr(Model):
    max: list[Expr] = Field(min_length=1, max_length=32)


class IfExpr(Model):
    if_: Expr = Field(alias="if", description="counts as true where it is not 0")
    then: Expr
    else_: Expr = Field(alias="else")


Expr = Finite | SensorExpr | PredictionExpr | AddExpr | MulExpr | MinExpr | MaxExpr | IfExpr
for _model in (AddExpr, MulExpr, MinExpr, MaxExpr, IfExpr):
    _model.model_rebuild()


def expr_children(expr: Expr) -> list[Expr]:
    """The direct sub-expressions of an expression."""
    if isinstance(expr, AddExpr):
        return list(expr.add)
    if isinstance(expr, MulExpr):
        return list(expr.mul)
    if isinstance(expr, MinExpr):
        return list(expr.min)
    if isinstance(expr, MaxExpr):
        return list(expr.max)
    if isinstance(expr, IfExpr):
        return [expr.if_, expr.then, expr.else_]
    return []


def raw_expr_problem(data: Any) -> str | None:
    """Why unvalidated expression data is too deep or too large, else None.

    Runs before pydantic validates the expression: a union validated on deeply nested input multiplies
    its errors level by level, so depth and size are checked first, iteratively, on the raw data.
    """
    stack: list[tuple[Any, int]] = [(data, 1)]
    nodes = 0
    while stack:
        value, depth = stack.pop()
        if isinstance(value, dict):
            nodes += 1
            if depth > MAX_EXPR_DEPTH:
                return f"nested more than {MAX_EXPR_DEPTH} expressions deep"
            for child in value.values():
                stack.extend((item, depth + 1) for item in (child if isinstance(child, list) else [child]))
        else:
            nodes += 1
        if nodes > MAX_EXPR_NODES:
            return f"has more than {MAX_EXPR_NODES} nodes"
    return None


def expr_size(expr: Expr) -> int:
    return 1 + sum(expr_size(child) for child in expr_children(expr))


def expr_predictions(expr: Expr) -> set[str]:
    """Names of the demons whose predictions an expression reads."""
    found = {expr.prediction} if isinstance(expr, PredictionExpr) else set()
    for child in expr_children(expr):
        found |= expr_predictions(child)
    return found


def expr_interval(expr: Expr, bounds: dict[str, tuple[float, float]]) -> tuple[float, float]:
    """The range an expression can take, given each sensor's range (predictions are unbounded)."""
    if isinstance(expr, float | int):
        return float(expr), float(expr)
    if isinstance(expr, SensorExpr):
        return bounds.get(expr.sensor, (-math.inf, math.inf))
    if isinstance(expr, PredictionExpr):
        return -math.inf, math.inf
    if isinstance(expr, IfExpr):
        (a, b), (c, d) = expr_interval(expr.then, bounds), expr_interval(expr.else_, bounds)
        return min(a, c), max(b, d)
    parts = [expr_interval(child, bounds) for child in expr_children(expr)]
    lo, hi = parts[0]
    for a, b in parts[1:]:
        if isinstance(expr, AddExpr):
            lo, hi = lo + a, hi + b
        elif isinstance(expr, MulExpr):
            products = [p for p in (lo * a, lo * b, hi * a, hi * b) if not math.isnan(p)]
            lo, hi = (min(products), max(products)) if products else (-math.inf, math.inf)
        elif isinstance(expr, MinExpr):
            lo, hi = min(lo, a), min(hi, b)
        else:
            lo, hi = max(lo, a), max(hi, b)
    return lo, hi


def expr_sensors(expr: Expr) -> set[str]:
    found = {expr.sensor} if isinstance(expr, SensorExpr) else set()
    for child in expr_children(expr):
        found |= expr_sensors(child)
    return found


# ----------------------------------------------------------------------------------------------
# The world (DESIGN section 2)

Rect = Annotated[list[Finite], Field(min_length=4, max_length=4, description="[x0, y0, x1, y1]")]


class Color(Model):
    name: Name
    value: Finite = Field(description="the value of the color:<indicator> sensor while inside")
    probability: Probability


class IndicatorReward(Model):
    indicator: Name
    values: dict[Name, Finite] = Field(description="terminal reward per colour of the indicator")


class Region(Model):
    name: Name
    kind: Literal["obstacle", "terminal", "zone", "indicator"]
    rect: Rect
    reward: Finite | IndicatorReward | None = Field(
        default=None, description="terminal regions only: a number or a reward per indicator colour"
    )
    colors: list[Color] | None = Field(default=None, max_length=MAX_COLORS, description="indicator regions only")

    @field_validator("rect")
    @classmethod
    def _ordered(cls, rect: list[float]) -> list[float]:
        if not (rect[0] < rect[2] and rect[1] < rect[3]):
            raise ValueError("rect must be [x0, y0, x1, y1] with x0 < x1 and y0 < y1")
        return rect

    @model_validator(mode="after")
    def _kind_fields(self) -> Region:
        if self.kind == "terminal" and self.reward is None:
            raise ValueError(f"terminal region {self.name!r} needs a reward")
        if self.kind != "terminal" and self.reward is not None:
            raise ValueError(f"only terminal regions have a reward ({self.name!r} is {self.kind})")
        if self.kind == "indicator":
            if not self.colors:
                raise ValueError(f"indicator {self.name!r} needs colors")
            names = [c.name for c in self.colors]
            if len(set(names)) != len(names):
                raise ValueError(f"indicator {self.name!r} has repeated colour names")
            if not math.isclose(sum(c.probability for c in self.colors), 1.0, abs_tol=1e-9):
                raise ValueError(f"the colour probabilities of {self.name!r} must sum to 1")
        elif self.colors is not None:
            raise ValueError(f"only indicator regions have colors ({self.name!r} is {self.kind})")
        return self


class WorldSpec(Model):
    """A continuous rectangle [0, width) x [0, height) with rectangular regions."""

    name: Name | None = None
    width: PositiveSize = 500.0
    height: PositiveSize = 500.0
    step: PositiveSize = 100.0
    slip: Probability = Field(default=0.0, description="probability of a perpendicular move")
    noise: Annotated[float, Field(ge=0.0, le=MAX_WORLD_SIZE)] = Field(
        default=0.0, description="std of Gaussian noise added to every move"
    )
    start: Annotated[list[Finite], Field(min_length=2, max_length=4)] = Field(
        default_factory=lambda: [0.0, 0.0], description="a point [x, y] or a rectangle [x0, y0, x1, y1]"
    )
    regions: list[Region] = Field(default_factory=list, max_length=MAX_REGIONS)
    transient_reward: Finite = -0.01
    max_steps: int = Field(default=100, ge=1, le=MAX_STEPS)

    @model_validator(mode="before")
    @classmethod
    def _grid_kind(cls, data: Any) -> Any:
        """`kind = "grid"` may be written; it is the default, and the grid world's spec does not keep it."""
        if isinstance(data, dict) and data.get("kind") == "grid":
            return {k: v for k, v in data.items() if k != "kind"}
        return data

    @property
    def kind(self) -> Literal["grid"]:
        return "grid"

    @field_validator("start")
    @classmethod
    def _start_shape(cls, start: list[float]) -> list[float]:
        if len(start) == 3:
            raise ValueError("start is a point [x, y] or a rectangle [x0, y0, x1, y1]")
        if len(start) == 4 and not (start[0] < start[2] and start[1] < start[3]):
            raise ValueError("a start rectangle needs x0 < x1 and y0 < y1")
        return start

    @model_validator(mode="after")
    def _consistent(self) -> WorldSpec:
        names = [r.name for r in self.regions]
        dupes = sorted({n for n in names if names.count(n) > 1})
        if dupes:
            raise ValueError(f"region names must be unique: {', '.join(dupes)}")
        by_name = {r.name: r for r in self.regions}
        for region in self.regions:
            if isinstance(region.reward, IndicatorReward):
                indicator = by_name.get(region.reward.indicator)
                if indicator is None or indicator.kind != "indicator":
                    raise ValueError(
                        f"terminal {region.name!r} names {region.reward.indicator!r}, which is no indicator"
                    )
                colors = {c.name for c in indicator.colors or []}
                if set(region.reward.values) != colors:
                    raise ValueError(
                        f"terminal {region.name!r} needs a reward for exactly the colours "
                        f"{sorted(colors)} of {indicator.name!r}"
                    )
        x, y = self.start[0], self.start[1]
        if not self.contains(x, y):
            raise ValueError("start must lie inside the world")
        if len(self.start) == 4 and not (self.start[2] <= self.width and self.start[3] <= self.height):
            raise ValueError("the start rectangle must lie inside the world")
        if len(self.start) == 2:
            for region in self.regions:
                x0, y0, x1, y1 = region.rect
                if region.kind in ("obstacle", "terminal") and x0 <= x < x1 and y0 <= y < y1:
                    raise ValueError(f"start lies inside {region.kind} {region.name!r}")
        elif not self.start_rect_has_free_cell():
            # Raised as a ValidationError so that the error names `start` (a model validator's would name the world).
            detail = InitErrorDetails(
                type=PydanticCustomError("impossible_start", IMPOSSIBLE_START), loc=("start",), input=self.start
            )
            raise ValidationError.from_exception_data(type(self).__name__, [detail])
        return self

    def contains(self, x: float, y: float) -> bool:
        """Whether (x, y) lies inside the world, [0, width) x [0, height) (the engines test arrays the same way)."""
        return 0 <= x < self.width and 0 <= y < self.height

    def start_rect_has_free_cell(self) -> bool:
        """Whether some part of the start rectangle lies outside every obstacle and terminal.

        The region edges cut the rectangle into cells that each lie wholly inside or wholly outside every
        region; the rectangle has room iff the centre of one cell is in none of the obstacles and terminals.
        """
        x0, y0, x1, y1 = self.start
        walls = [r.rect for r in self.regions if r.kind in ("obstacle", "terminal")]
        walls = [r for r in walls if r[0] < x1 and x0 < r[2] and r[1] < y1 and y0 < r[3]]  # those that meet it
        xs = sorted({x0, x1, *(e for r in walls for e in (r[0], r[2]) if x0 < e < x1)})
        ys = sorted({y0, y1, *(e for r in walls for e in (r[1], r[3]) if y0 < e < y1)})
        for cx in (a + (b - a) / 2 for a, b in itertools.pairwise(xs)):
            for cy in (a + (b - a) / 2 for a, b in itertools.pairwise(ys)):
                if not any(r[0] <= cx < r[2] and r[1] <= cy < r[3] for r in walls):
                    return True
        return False

    def sensor_bounds(self) -> dict[str, tuple[float, float]]:
        """The range of every sensor (for checking that continuations stay within [0, 1])."""
        rewards = [0.0]
        for region in self.regions:
            if isinstance(region.reward, IndicatorReward):
                rewards += list(region.reward.values.values())
            elif region.reward is not None:
                rewards.append(float(region.reward))
        bounds = {
            "x": (0.0, self.width),
            "y": (0.0, self.height),
            "bump": (0.0, 1.0),
            "steps": (0.0, float(self.max_steps)),
            # An episode's first state reads reward 0 (no transition yet), whatever the transient reward.
            "reward": (min(0.0, self.transient_reward + min(rewards)), max(0.0, self.transient_reward + max(rewards))),
            "terminal": (0.0, 1.0),
        }
        for region in self.regions:
            bounds[f"in:{region.name}"] = (0.0, 1.0)
            if region.kind == "indicator":
                values = [0.0] + [c.value for c in region.colors or []]
                bounds[f"color:{region.name}"] = (min(values), max(values))
        return bounds

    def sensor_names(self) -> list[str]:
        """The sensor vector's names, in its fixed order (DESIGN section 2)."""
        names = ["x", "y", "bump", "steps", "reward"]
        names += [f"in:{r.name}" for r in self.regions]
        names += [f"color:{r.name}" for r in self.regions if r.kind == "indicator"]
        names.append("terminal")
        return names

    def num_actions(self) -> int:
        """Up, down, left, right."""
        return len(ACTIONS)


# ----------------------------------------------------------------------------------------------
# Other world kinds (DESIGN section 2, last item): a Gymnasium environment, a live stream of observations.
# Each keeps the grid world's contract: named sensors with ranges, a number of actions, terminated apart
# from truncated. `world.kind` tells them apart; a world without `kind` is the grid world.

MAX_ACTIONS = 64
MAX_SENSORS = 1024
SensorName = Annotated[str, Field(min_length=1, max_length=80, pattern=r"^[A-Za-z_][A-Za-z0-9_.:-]*$")]


class SensorRange(Model):
    """One sensor of a non-grid world: its name and, where known, the range its readings stay in."""

    name: SensorName
    low: Finite | None = Field(default=None, description="the lowest reading (a bound or a documented range)")
    high: Finite | None = Field(default=None, description="the highest reading")

    @model_validator(mode="after")
    def _ordered(self) -> SensorRange:
        if self.low is not None and self.high is not None and not self.low < self.high:
            raise ValueError(f"sensor {self.name!r}: low must be below high")
        return self


def _sensor_bounds(sensors: list[SensorRange]) -> dict[str, tuple[float, float]]:
    return {s.name: (-math.inf if s.low is None else s.low, math.inf if s.high is None else s.high) for s in sensors}


def _unique_sensors(sensors: list[SensorRange]) -> list[SensorRange]:
    names = [s.name for s in sensors]
    dupes = sorted({n for n in names if names.count(n) > 1})
    if dupes:
        raise ValueError(f"sensor names must be unique: {', '.join(dupes)}")
    return sensors


class StreamWorldSpec(Model):
    """Observations a client pushes (a robot, a recorded log): the sensors it sends and its number of actions.

    A record is (observation: one reading per sensor, in this order; the action taken; optionally the
    behaviour's probabilities of every action, uniform when left out). The stream is one continuing
    episode: nothing terminates it.
    """

    kind: Literal["stream"]
    name: Name | None = None
    sensors: list[SensorRange] = Field(min_length=1, max_length=MAX_SENSORS)
    actions: int = Field(ge=1, le=MAX_ACTIONS, description="the number of actions a record's action is one of")

    @field_validator("sensors")
    @classmethod
    def _unique(cls, sensors: list[SensorRange]) -> list[SensorRange]:
        return _unique_sensors(sensors)

    def sensor_names(self) -> list[str]:
        return [s.name for s in self.sensors]

    def sensor_bounds(self) -> dict[str, tuple[float, float]]:
        return _sensor_bounds(self.sensors)

    def num_actions(self) -> int:
        return self.actions


class GymnasiumWorldSpec(Model):
    """An installed Gymnasium environment with a `Box` (or `Discrete`) observation and a `Discrete` action space.

    Its sensors are the observation's components (named and ranged by `horde.worlds.gym_spaces`), then
    `reward`, `terminated` and `truncated`, read after every step (0 at an episode's first state).
    """

    kind: Literal["gymnasium"]
    name: Name | None = None
    id: str = Field(
        min_length=1,
        max_length=120,
        pattern=r"^[A-Za-z0-9_./-]+$",  # no "module:Env" form: an id never makes the server import a module
        description="a registered environment id, e.g. MountainCar-v0 (or horde/Baird-v0, Baird's counterexample)",
    )
    max_steps: int | None = Field(
        default=None, ge=1, le=MAX_STEPS, description="truncate episodes here (default: the environment's own limit)"
    )
    _sensors: list[SensorRange] = PrivateAttr(default_factory=list)
    _actions: int = PrivateAttr(default=0)

    @model_validator(mode="after")
    def _installed(self) -> GymnasiumWorldSpec:
        from horde.worlds.gym_spaces import GymSpaceError, describe  # gymnasium is imported only for this kind

        try:
            sensors, actions = describe(self.id)
        except GymSpaceError as exc:  # a ValidationError at `id`, so that the 422 names the field
            detail = InitErrorDetails(type=PydanticCustomError("gymnasium_id", str(exc)), loc=("id",), input=self.id)
            raise ValidationError.from_exception_data(type(self).__name__, [detail]) from None
        self._sensors = sensors
        self._actions = actions
        return self

    def sensor_ranges(self) -> list[SensorRange]:
        """The observation's components with their ranges, then reward, terminated and truncated."""
        return list(self._sensors)

    def sensor_names(self) -> list[str]:
        return [s.name for s in self._sensors]

    def sensor_bounds(self) -> dict[str, tuple[float, float]]:
        return _sensor_bounds(self._sensors)

    def num_actions(self) -> int:
        return self._actions


WORLD_KINDS = ("grid", "gymnasium", "stream")


def _error_detail(error: Any, loc: tuple[Any, ...]) -> InitErrorDetails:
    """A pydantic error again, at another loc (custom error types are rebuilt from their message)."""
    ctx = error.get("ctx")
    try:
        detail = InitErrorDetails(type=error["type"], loc=loc, input=error["input"])
        if ctx:
            detail["ctx"] = ctx
        ValidationError.from_exception_data("check", [detail])
    except (KeyError, TypeError):
        detail = InitErrorDetails(type=PydanticCustomError(error["type"], error["msg"]), loc=loc, input=error["input"])
    return detail


def _world_kind(value: Any) -> str:
    if isinstance(value, dict):
        return str(value.get("kind", "grid"))
    return str(getattr(value, "kind", "grid"))


AnyWorldSpec = Annotated[
    Annotated[WorldSpec, Tag("grid")]
    | Annotated[GymnasiumWorldSpec, Tag("gymnasium")]
    | Annotated[StreamWorldSpec, Tag("stream")],
    Discriminator(_world_kind),
]


# ----------------------------------------------------------------------------------------------
# Features (DESIGN section 3)


class Condition(Model):
    demon: Name
    thresholds: list[Finite] = Field(min_length=1, max_length=15)

    @field_validator("thresholds")
    @classmethod
    def _sorted(cls, thresholds: list[float]) -> list[float]:
        if any(b <= a for a, b in itertools.pairwise(thresholds)):
            raise ValueError("thresholds must be strictly increasing")
        return thresholds


class TiledSensor(Model):
    """One sensor of `kind = "sensors"` features: its readings in [low, high] are tiled (and clipped)."""

    sensor: str = Field(min_length=1, max_length=80, description="a sensor name, e.g. in:zone3")
    low: Finite = Field(description="the lowest reading the tiling resolves")
    high: Finite = Field(description="the highest reading the tiling resolves")

    @model_validator(mode="after")
    def _ordered(self) -> TiledSensor:
        if not self.low < self.high:
            raise ValueError(f"sensor {self.sensor!r}: low must be below high")
        return self


MAX_TILED_SENSORS = 256
MAX_TABLE_VALUES = 4096  # readings of a table's discrete sensor
MAX_TABLE_ACTIVE = 64  # indices listed per reading
FeatureIndex = Annotated[int, Field(ge=0, lt=MAX_FEATURES)]
TableRow = Annotated[list[FeatureIndex], Field(min_length=1, max_length=MAX_TABLE_ACTIVE)]


class FeatureSpec(Model):
    kind: Literal["stripes", "tiles", "grid", "constant", "sensors", "table"] = "stripes"
    parts: int = Field(default=5, ge=1, le=1000, description="stripes: columns, rows, diagonals")
    tilings: int = Field(default=8, ge=1, le=64, description="tiles, sensors: number of offset tilings")
    tiles: int = Field(default=8, ge=1, le=1000, description="tiles, grid, sensors: tiles per dimension")
    sensors: list[TiledSensor] | None = Field(
        default=None, max_length=MAX_TILED_SENSORS, description="sensors: each tiled on its own, with its range"
    )
    size: int | None = Field(
        default=None,
        ge=1,
        le=MAX_FEATURES - 1,
        description="sensors: the hash table's size (features besides the bias)",
    )
    sensor: SensorName | None = Field(
        default=None, description="table: the discrete sensor whose reading (0, 1, 2, ...) picks a row of the table"
    )
    table: list[TableRow] | None = Field(
        default=None,
        max_length=MAX_TABLE_VALUES,
        description="table: per reading of the sensor, its active feature indices (all rows of one length); an "
        "index listed twice is a feature of value 2 there (Baird's counterexample)",
    )
    condition: Condition | None = None

    @field_validator("size")
    @classmethod
    def _fits(cls, size: int | None, info: ValidationInfo) -> int | None:
        tilings, sensors = info.data.get("tilings"), info.data.get("sensors")
        if size is not None and tilings is not None and sensors and size < tilings * len(sensors):
            raise ValueError(
                f"size {size} is too small for {tilings} tilings of {len(sensors)} sensors "
                f"(at least {tilings * len(sensors)})"
            )
        return size

    @model_validator(mode="after")
    def _bounded(self) -> FeatureSpec:
        if self.kind == "sensors":
            if not self.sensors:
                raise ValueError("sensors features need a list of sensors, each with its range [low, high]")
            if self.size is None:
                raise ValueError("sensors features need a hash table size")
        elif self.sensors is not None or self.size is not None:
            raise ValueError("sensors and size belong to kind = 'sensors' features")
        if self.kind == "table":
            if self.sensor is None or not self.table:
                raise ValueError("table features need a sensor and a table: one row of active indices per reading")
            lengths = sorted({len(row) for row in self.table})
            if len(lengths) > 1:
                raise ValueError(f"every row of the table lists the same number of indices (found {lengths})")
        elif self.sensor is not None or self.table is not None:
            raise ValueError("sensor and table belong to kind = 'table' features")
        if self.state_size() > MAX_FEATURES:
            raise ValueError(f"at most {MAX_FEATURES} state features (this spec has {self.state_size()})")
        return self

    def base_size(self) -> int:
        """Number of state features before conditioning."""
        if self.kind == "stripes":
            return 2 * self.parts + 2 * (2 * self.parts - 1) + 1
        if self.kind == "tiles":
            return self.tilings * (self.tiles + 1) ** 2 + 1
        if self.kind == "grid":
            return self.tiles**2
        if self.kind == "sensors":
            return (self.size or 0) + 1
        if self.kind == "table":
            return 1 + max(max(row) for row in self.table or [[0]])
        return 1

    def has_repeats(self) -> bool:
        """Whether a row of a table lists an index more than once (a feature value above 1)."""
        return any(len(set(row)) < len(row) for row in self.table or [])

    def active_count(self) -> int:
        """Number of active state features (indices listed, for a table), the same in every state."""
        if self.kind == "sensors":
            return self.tilings * len(self.sensors or []) + 1
        if self.kind == "table":
            return len((self.table or [[0]])[0])
        return {"stripes": 5, "tiles": self.tilings + 1, "grid": 1, "constant": 1}[self.kind]

    def state_size(self) -> int:
        blocks = len(self.condition.thresholds) + 1 if self.condition else 1
        return self.base_size() * blocks


# ----------------------------------------------------------------------------------------------
# Policies (DESIGN section 4)

PolicyKind = Literal["uniform", "fixed", "greedy", "softmax", "epsilon_greedy", "of", "sign"]
OWN_VALUE_POLICIES = ("greedy", "softmax", "epsilon_greedy")


def _policy_shorthand(value: Any) -> Any:
    """Accept "uniform", "softmax", {of = "base"} besides the full {kind = ...} form."""
    if isinstance(value, str):
        return {"kind": value}
    if isinstance(value, dict) and "kind" not in value and set(value) == {"of"}:
        return {"kind": "of", "demon": value["of"]}
    return value


def _sign_fields(policy: PolicySpec | BehaviourSpec) -> None:
    """A "sign" policy names its sensor and its two actions; no other kind does."""
    if policy.kind == "sign" and (policy.sensor is None or policy.actions is None):
        raise ValueError("a sign policy names a sensor and actions = [action where negative, action where >= 0]")
    if policy.kind != "sign" and (policy.sensor is not None or policy.actions is not None):
        raise ValueError(f"sensor and actions belong to sign policies (this one is {policy.kind!r})")


class PolicySpec(Model):
    """A target policy. Shorthands: "uniform", "greedy", "softmax", {of = "demon"}."""

    kind: PolicyKind = "uniform"
    probabilities: list[Probability] | None = Field(
        default=None,
        min_length=1,
        max_length=MAX_ACTIONS,
        description="fixed: one per action of the world ([up, down, left, right] in the grid world)",
    )
    temperature: Annotated[float, Field(gt=0.0, le=1e6, allow_inf_nan=False)] = 1.0
    epsilon: Probability = 0.1
    demon: Name | None = Field(default=None, description="of: the demon whose policy this follows")
    sensor: SensorName | None = Field(default=None, description="sign: the sensor whose sign chooses the action")
    actions: list[Annotated[int, Field(ge=0, lt=MAX_ACTIONS)]] | None = Field(
        default=None, min_length=2, max_length=2, description="sign: [action where negative, action where >= 0]"
    )

    _shorthand = model_validator(mode="before")(_policy_shorthand)

    @model_validator(mode="after")
    def _fields(self) -> PolicySpec:
        _sign_fields(self)
        if self.kind == "fixed":
            if self.probabilities is None:
                raise ValueError("a fixed policy needs probabilities [up, down, left, right]")
            if not math.isclose(sum(self.probabilities), 1.0, abs_tol=1e-9):
                raise ValueError("fixed probabilities must sum to 1")
        elif self.probabilities is not None:
            raise ValueError("probabilities belong to fixed policies only")
        if self.kind == "of" and self.demon is None:
            raise ValueError("an 'of' policy names the demon it follows")
        if self.kind != "of" and self.demon is not None:
            raise ValueError(f"only 'of' policies name a demon (this one is {self.kind!r})")
        return self


class BehaviourSpec(Model):
    """The behaviour policy of a run: uniform, fixed, or greedy/softmax/epsilon_greedy over a control demon."""

    kind: Literal["uniform", "fixed", "greedy", "softmax", "epsilon_greedy", "sign"] = "uniform"
    demon: Name | None = None
    probabilities: list[Probability] | None = Field(default=None, min_length=1, max_length=MAX_ACTIONS)
    temperature: Annotated[float, Field(gt=0.0, le=1e6, allow_inf_nan=False)] = 1.0
    epsilon: Probability = 0.1
    sensor: SensorName | None = Field(default=None, description="sign: the sensor whose sign chooses the action")
    actions: list[Annotated[int, Field(ge=0, lt=MAX_ACTIONS)]] | None = Field(
        default=None, min_length=2, max_length=2, description="sign: [action where negative, action where >= 0]"
    )

    _shorthand = model_validator(mode="before")(_policy_shorthand)

    @model_validator(mode="after")
    def _fields(self) -> BehaviourSpec:
        _sign_fields(self)
        if self.kind == "sign" and self.epsilon <= 0.0:
            raise ValueError("a sign behaviour needs epsilon > 0, so that every action has a positive probability")
        if self.kind in OWN_VALUE_POLICIES and self.demon is None:
            raise ValueError(f"a {self.kind} behaviour names the control demon it acts on")
        if self.kind in ("uniform", "fixed") and self.demon is not None:
            raise ValueError(f"a {self.kind} behaviour needs no demon")
        if self.kind == "fixed":
            if self.probabilities is None or not math.isclose(sum(self.probabilities), 1.0, abs_tol=1e-9):
                raise ValueError("a fixed behaviour needs probabilities [up, down, left, right] summing to 1")
            if min(self.probabilities) <= 0.0:
                raise ValueError("a fixed behaviour must give every action a positive probability")
        return self


# ----------------------------------------------------------------------------------------------
# Demons and learning (DESIGN sections 4 and 5)

Learner = Literal["gq", "gtd", "td", "true_online_td", "true_online_gtd", "etd"]
StepSize = Literal["constant", "autostep", "tidbd"]
# Which step-size adaptation each learner has a published form for (README "Learners and step sizes").
STEP_SIZE_LEARNERS: dict[str, tuple[str, ...]] = {
    "constant": ("gq", "gtd", "td", "true_online_td", "true_online_gtd", "etd"),
    "autostep": ("td",),  # AutoTIDBD (Kearney et al. 2019): Autostep (Mahmood et al. 2012) for TD(lambda)
    "tidbd": ("td",),  # TIDBD(lambda) (Kearney et al. 2019), semi-gradient
}
WHY_NOT_ADAPTIVE = (
    "Autostep and TIDBD are derived for TD(lambda) only (Mahmood, Sutton, Degris & Pilarski 2012 for supervised "
    "learning; Kearney, Veeriah, Travnik, Pilarski & Sutton 2019 for TD(lambda)); no paper defines their "
    "meta-gradient for the gradient-corrected (gq, gtd, true_online_gtd), true online or emphatic learners"
)
MetaStep = Annotated[float, Field(ge=0.0, le=1.0, allow_inf_nan=False)]
AutostepTau = Annotated[float, Field(ge=1.0, le=1e9, allow_inf_nan=False)]


def demon_step_size(demon: DemonSpec, learning: LearningSpec) -> tuple[str, float]:
    """A demon's step-size mode and meta step size: its own, else [learning]'s where its learner has that mode."""
    mode = demon.step_size
    if mode is None:
        mode = learning.step_size if step_size_problem(demon.learner, learning.step_size) is None else "constant"
    meta = demon.meta_step if demon.meta_step is not None else learning.meta_step
    return mode, meta


def step_size_problem(learner: str, step_size: str) -> str | None:
    """Why a learner x step-size combination is undefined, or None when a paper defines it."""
    if learner in STEP_SIZE_LEARNERS[step_size]:
        return None
    return f"step_size {step_size!r} is not defined for learner {learner!r}: {WHY_NOT_ADAPTIVE}"


class DemonSpec(Model):
    """A question (policy, cumulant, outcome, continuation) and its answer (features, learner, step sizes)."""

    name: Name
    policy: PolicySpec = Field(default_factory=PolicySpec)
    cumulant: Expr = 0.0
    outcome: Expr = 0.0
    continuation: Expr = 1.0
    discount: Probability = 1.0
    learner: Learner = Field(
        default="gq",
        description="gq: action values (GQ(lambda)); gtd, td, true_online_td, true_online_gtd, etd: state values",
    )
    features: FeatureSpec | None = Field(default=None, description="defaults to the run's features")
    lambda_: Probability | None = Field(default=None, alias="lambda")
    alpha: Annotated[float, Field(ge=0.0, le=10.0, allow_inf_nan=False)] | None = Field(
        default=None, description="step size before division by the number of active features"
    )
    alpha_w: Annotated[float, Field(ge=0.0, le=10.0, allow_inf_nan=False)] | None = Field(
        default=None, description="step size of the secondary weights, also divided by the active count"
    )
    reset: Literal["never", "episode"] = "never"
    step_size: StepSize | None = Field(
        default=None,
        description="constant (alpha as given), autostep or tidbd (per-weight step sizes adapted online, "
        "starting from alpha); defaults to the run's [learning] step_size",
    )
    meta_step: MetaStep | None = Field(
        default=None, description="meta step size of autostep (mu) or tidbd (theta); defaults to [learning]"
    )
    initial_weights: list[Finite] | None = Field(
        default=None,
        max_length=MAX_FEATURES,
        description="the weights the demon starts from (and a run reset restores), one per feature (gq: per "
        "feature of every action's block, action by action); default all 0",
    )

    @field_validator("cumulant", "outcome", "continuation", mode="before")
    @classmethod
    def _bounded_expr(cls, value: Any) -> Any:
        problem = raw_expr_problem(value)
        if problem is not None:
            raise ValueError(f"this expression is {problem}" if "nested" in problem else f"this expression {problem}")
        return value

    @model_validator(mode="after")
    def _consistent(self) -> DemonSpec:
        for field in ("cumulant", "outcome", "continuation"):
            if expr_size(getattr(self, field)) > MAX_EXPR_NODES:
                raise ValueError(f"{field} has more than {MAX_EXPR_NODES} nodes")
        if self.learner != "gq" and self.policy.kind in OWN_VALUE_POLICIES:
            raise ValueError(
                f"a {self.policy.kind} target policy needs action values: use learner 'gq', not {self.learner!r}"
            )
        if self.step_size is not None and (problem := step_size_problem(self.learner, self.step_size)):
            raise ValueError(problem)
        if self.initial_weights is not None and self.reset == "episode":
            raise ValueError("initial_weights and reset = 'episode' do not go together: a demon that forgets its "
                             "weights at every episode start starts each episode from 0")  # fmt: skip
        return self


class LearningSpec(Model):
    """Defaults for demons that do not set their own, chosen by `studies/stepsizes.toml` (see README)."""

    lambda_: Probability = Field(default=0.9, alias="lambda")
    alpha: Annotated[float, Field(ge=0.0, le=10.0, allow_inf_nan=False)] = 0.03
    alpha_w: Annotated[float, Field(ge=0.0, le=10.0, allow_inf_nan=False)] = 0.0001
    step_size: StepSize = Field(
        default="constant",
        description="the step-size mode of demons that set none; an adaptive mode applies only to the learners "
        "it is defined for (td), the others keep constant step sizes",
    )
    meta_step: MetaStep = Field(default=0.01, description="autostep's mu and tidbd's theta (meta step size)")
    autostep_tau: AutostepTau = Field(
        default=10_000.0, description="autostep's time scale tau of its normaliser v (Mahmood et al. 2012: 1e4)"
    )


# ----------------------------------------------------------------------------------------------
# Protocol (trials x episodes x max steps; evaluation; test runs)


class StopRule(Model):
    """Stop a trial early once no weight moved by more than `tolerance` over `window` episodes."""

    window: int = Field(default=100, ge=1, le=MAX_EPISODES)
    tolerance: Annotated[float, Field(gt=0.0, allow_inf_nan=False)] = 1e-3


class EvaluationSpec(Model):
    """Monte-Carlo truth at the start point after each trial."""

    rollouts: int = Field(default=1000, ge=0, le=100_000)
    cap: int = Field(default=10_000, ge=1, le=MAX_STEPS, description="rollout length limit")
    demons: list[Name] | None = Field(default=None, description="which demons; default all prediction demons")
    states: int = Field(
        default=20,
        ge=1,
        le=1000,
        description="Gymnasium worlds: test states, from a run of the behaviour after learning",
    )


class TestSpec(Model):
    """Test runs after each trial: the behaviour below, no learning except reset-each-episode demons."""

    runs: int = Field(default=100, ge=1, le=100_000)
    behaviour: BehaviourSpec


class ProtocolSpec(Model):
    trials: int = Field(default=1, ge=1, le=MAX_TRIALS)
    episodes: int = Field(default=1000, ge=0, le=MAX_EPISODES)
    stop: StopRule | None = None
    evaluation: EvaluationSpec = Field(default_factory=EvaluationSpec)
    test: TestSpec | None = None


class Counts(Model):
    positive: int = Field(ge=0)
    negative: int = Field(ge=0)
    none: int = Field(ge=0)


class ThesisResults(Model):
    """The thesis's numbers, shown beside ours."""

    predictions: dict[Name, Finite] = Field(default_factory=dict)
    counts: Counts | None = None


# ----------------------------------------------------------------------------------------------
# Demon families: one entry, the product of its lists (Horde scale that a user can write)

MAX_FAMILIES = 64
_PLACEHOLDER = re.compile(r"\{([A-Za-z_][A-Za-z0-9_]*)\}")


def _fill(template: Any, env: dict[str, str | float]) -> Any:
    """The template with every "{var}" replaced: a string that is only "{var}" becomes the value itself."""
    if isinstance(template, str):
        whole = _PLACEHOLDER.fullmatch(template)
        if whole and whole.group(1) in env:
            return env[whole.group(1)]
        return _PLACEHOLDER.sub(lambda m: str(env[m.group(1)]) if m.group(1) in env else m.group(0), template)
    if isinstance(template, dict):
        return {key: _fill(value, env) for key, value in template.items()}
    if isinstance(template, list):
        return [_fill(value, env) for value in template]
    return template


def _part(parts: dict[str, str], match: re.Match[str]) -> str:
    return parts[match.group(1)]


class DemonFamily(Model):
    """One entry that expands into a demon for every combination of its lists (their product).

    `demon` is a demon written as usual, in which any "{var}" stands for the values of the list `var`
    of `over`; `name` is the pattern of the demons' names, such as "{sensor}_g{gamma}" (characters a
    name cannot hold, such as the colon of "in:zone1", become "_"). A 422 about a family names the field
    and the rule, never the pattern or a demon name made of it (they are input).
    """

    over: dict[Name, Annotated[list[Annotated[str, Field(max_length=80)] | Finite], Field(min_length=1)]] = Field(
        min_length=1, max_length=8, description="the lists whose product the family expands into"
    )
    name: str = Field(min_length=1, max_length=64, description='the name pattern, e.g. "{sensor}_g{gamma}"')
    demon: dict[str, Any] = Field(description='a demon without its name; "{var}" in any string takes the values')
    _demons: list[DemonSpec] = PrivateAttr(default_factory=list)

    @field_validator("over")
    @classmethod
    def _bounded(cls, over: dict[str, list[str | float]]) -> dict[str, list[str | float]]:
        count = math.prod(len(values) for values in over.values())
        if count > MAX_DEMONS:
            raise ValueError(f"the lists expand into {count} demons, more than {MAX_DEMONS}")
        return over

    @field_validator("name")
    @classmethod
    def _pattern_fits_over(cls, name: str, info: ValidationInfo) -> str:
        over = info.data.get("over")
        if over is None:  # over is invalid itself, and its own error says so
            return name
        used = set(_PLACEHOLDER.findall(name))
        unknown = sorted(used - set(over))
        if unknown:  # placeholders are identifiers ([A-Za-z_][A-Za-z0-9_]*): naming them echoes no markup
            raise ValueError(f"every {{placeholder}} must be a list of over ({', '.join(unknown)} is not)")
        missing = sorted(set(over) - used)
        if missing:
            raise ValueError(f"must use every list of over as a {{placeholder}} (missing: {', '.join(missing)})")
        for i, (_, demon_name) in enumerate(_combinations(name, over)):
            if not (len(demon_name) <= NAME_MAX and _NAME.fullmatch(demon_name)):
                raise ValueError(f"must make demon names of {NAME_RULE}; combination {i + 1} of over does not")
        return name

    @model_validator(mode="after")
    def _names(self) -> DemonFamily:
        if "name" in self.demon:
            raise ValueError("the demon template takes its name from the family's name pattern")
        self._demons = self._expand()
        return self

    def size(self) -> int:
        return math.prod(len(values) for values in self.over.values())

    def expand(self) -> list[DemonSpec]:
        """The family's demons, in the order of the product of its lists (the last list varies fastest)."""
        return list(self._demons)

    def _expand(self) -> list[DemonSpec]:
        """The demons of `expand`, validated.

        Raises:
            ValueError: naming the first combination whose filled-in template is not a valid demon, and the field.
        """
        demons = []
        for i, (env, name) in enumerate(_combinations(self.name, self.over)):
            try:
                demons.append(DemonSpec.model_validate({**_fill(self.demon, env), "name": name}))
            except ValidationError as exc:
                error = exc.errors()[0]
                where = ".".join(str(part) for part in error["loc"])
                raise ValueError(f"demon: combination {i + 1} of over: {where}: {error['msg']}") from None
        return demons


def _combinations(pattern: str, over: dict[str, list[str | float]]) -> Iterator[tuple[dict[str, str | float], str]]:
    """(values, demon name) of every combination of `over`'s lists, the last list varying fastest."""
    keys = list(over)
    for values in itertools.product(*(over[key] for key in keys)):
        env = dict(zip(keys, values, strict=True))
        parts = {key: re.sub(r"[^A-Za-z0-9_.-]", "_", str(value)) for key, value in env.items()}
        yield env, _PLACEHOLDER.sub(partial(_part, parts), pattern)


class RunSpec(Model):
    name: Name | None = None
    description: str = Field(default="", max_length=2000)
    world: AnyWorldSpec = Field(default_factory=WorldSpec)
    features: FeatureSpec = Field(default_factory=FeatureSpec)
    behaviour: BehaviourSpec = Field(default_factory=BehaviourSpec)
    learning: LearningSpec = Field(default_factory=LearningSpec)
    demons: list[DemonSpec] = Field(default_factory=list, max_length=MAX_DEMONS)
    families: list[DemonFamily] = Field(
        default_factory=list,
        max_length=MAX_FAMILIES,
        description="demon families, expanded into `demons` when the spec is read (and then empty)",
    )
    protocol: ProtocolSpec = Field(default_factory=ProtocolSpec)
    thesis: ThesisResults = Field(default_factory=ThesisResults)
    seed: int = Field(default=0, ge=0, le=2**63 - 1)

    @field_validator("families")
    @classmethod
    def _families_bounded(cls, families: list[DemonFamily], info: ValidationInfo) -> list[DemonFamily]:
        demons = len(info.data.get("demons") or [])
        total = demons + sum(f.size() for f in families)
        if total > MAX_DEMONS:
            raise ValueError(f"the families expand into {total - demons} demons; with {demons} others that is "
                             f"{total}, more than {MAX_DEMONS}")  # fmt: skip
        return families

    @model_validator(mode="wrap")
    @classmethod
    def _world_locs(cls, data: Any, handler: Any) -> Any:
        """Errors inside the world name its field as `world.<field>`, without the union's tag (grid, ...)."""
        try:
            return handler(data)
        except ValidationError as exc:
            errors = exc.errors()
            if not any(len(e["loc"]) > 1 and e["loc"][0] == "world" and e["loc"][1] in WORLD_KINDS for e in errors):
                raise
            details = []
            for e in errors:
                loc = e["loc"]
                if len(loc) > 1 and loc[0] == "world" and loc[1] in WORLD_KINDS:
                    loc = (loc[0], *loc[2:])
                details.append(_error_detail(e, loc))
            raise ValidationError.from_exception_data(cls.__name__, details) from None

    @property
    def grid(self) -> WorldSpec:
        """The world, for what only the grid world has (positions, regions, a lattice, a start).

        Raises:
            ValueError: the world is another kind (a Gymnasium environment or a stream).
        """
        if not isinstance(self.world, WorldSpec):
            raise ValueError(f"this needs the grid world; the run's world is of kind {self.world.kind!r}")
        return self.world

    @model_validator(mode="after")
    def _references(self) -> RunSpec:
        if self.families:  # expanded once, before anything reads the demons
            expanded = [demon for family in self.families for demon in family.expand()]
            object.__setattr__(self, "demons", [*self.demons, *expanded])
            object.__setattr__(self, "families", [])
        check_demon_graph(self)
        _check_demon_features(self)
        return self


def demon_dependencies(demon: DemonSpec, default_features: FeatureSpec) -> set[str]:
    """Names of the demons whose predictions or policies this demon reads."""
    deps: set[str] = set()
    for expr in (demon.cumulant, demon.outcome, demon.continuation):
        deps |= expr_predictions(expr)
    if demon.policy.kind == "of" and demon.policy.demon:
        deps.add(demon.policy.demon)
    features = demon.features or default_features
    if features.condition:
        deps.add(features.condition.demon)
    return deps


def check_demon_graph(spec: RunSpec) -> list[str]:
    """Validate names, references and sensors; return the demons in dependency order.

    Raises:
        ValueError: a repeated name, a reference to an unknown demon or sensor, or a cycle.
    """
    by_name: dict[str, DemonSpec] = {}
    for demon in spec.demons:
        if demon.name in by_name:
            raise ValueError(f"demon names must be unique: {demon.name!r} appears twice")
        by_name[demon.name] = demon
    sensors = set(spec.world.sensor_names())
    deps: dict[str, set[str]] = {}
    for demon in spec.demons:
        deps[demon.name] = demon_dependencies(demon, spec.features)
        for other in sorted(deps[demon.name]):
            if other not in by_name:
                raise ValueError(f"demon {demon.name!r} refers to unknown demon {other!r}")
        for field in ("cumulant", "outcome", "continuation"):
            for sensor in sorted(expr_sensors(getattr(demon, field))):
                if sensor not in sensors:
                    raise ValueError(
                        f"demon {demon.name!r}: {field} reads unknown sensor {sensor!r} "
                        f"(known: {', '.join(sorted(sensors))})"
                    )
        low, high = expr_interval(demon.continuation, spec.world.sensor_bounds())
        if math.isfinite(low) and math.isfinite(high) and (low < 0.0 or high > 1.0):
            raise ValueError(
                f"demon {demon.name!r}: continuation can take values in [{low:g}, {high:g}]; it must stay in [0, 1]"
            )
        if demon.policy.kind == "of" and demon.policy.demon in by_name:
            followed = by_name[demon.policy.demon]
            if followed.learner != "gq" and followed.policy.kind in OWN_VALUE_POLICIES:
                raise ValueError(f"demon {demon.name!r} follows {followed.name!r}, which has no policy")
    if spec.behaviour.demon is not None:
        control = by_name.get(spec.behaviour.demon)
        if control is None:
            raise ValueError(f"the behaviour refers to unknown demon {spec.behaviour.demon!r}")
        if control.learner != "gq":
            raise ValueError(f"the behaviour acts on {control.name!r}, which learns no action values")
    for where, features in [("features", spec.features)] + [(d.name, d.features) for d in spec.demons]:
        for tiled in (features.sensors or []) if features is not None else []:
            if tiled.sensor not in sensors:
                raise ValueError(
                    f"{where}: tiles unknown sensor {tiled.sensor!r} (known: {', '.join(sorted(sensors))})"
                )
    test = spec.protocol.test
    if test and test.behaviour.demon is not None and test.behaviour.demon not in by_name:
        raise ValueError(f"the test behaviour refers to unknown demon {test.behaviour.demon!r}")
    _check_world_fit(spec, by_name)
    actions = spec.world.num_actions()
    total = sum((d.features or spec.features).state_size() * (actions if d.learner == "gq" else 1) for d in spec.demons)
    if total > 50 * MAX_FEATURES:
        raise ValueError(f"the demons' weights would hold {total} numbers, more than {50 * MAX_FEATURES}")
    return topological_order(deps)


def _check_world_fit(spec: RunSpec, by_name: dict[str, DemonSpec]) -> None:
    """Policies over the world's own actions; features other worlds can code (sensors or constant).

    Raises:
        ValueError: naming the demon (or behaviour) whose probabilities or features do not fit the world.
    """
    actions = spec.world.num_actions()
    behaviours = [("the behaviour", spec.behaviour)]
    if spec.protocol.test is not None:
        behaviours.append(("the test behaviour", spec.protocol.test.behaviour))
    for where, policy in [(f"demon {d.name!r}: policy", d.policy) for d in by_name.values()] + behaviours:
        if policy.probabilities is not None and len(policy.probabilities) != actions:
            raise ValueError(f"{where}: probabilities has {len(policy.probabilities)} entries; the world has "
                             f"{actions} actions")  # fmt: skip
        if policy.kind == "sign":
            if isinstance(spec.world, WorldSpec):
                raise ValueError(f"{where}: a sign policy needs a world fed from outside (gymnasium or stream)")
            if policy.sensor not in spec.world.sensor_names():
                raise ValueError(f"{where}: sign reads unknown sensor {policy.sensor!r}")
            if max(policy.actions or [0]) >= actions:
                raise ValueError(f"{where}: actions {policy.actions} are not among the world's {actions} actions")
    if isinstance(spec.world, WorldSpec):
        return
    for where, features in [("features", spec.features)] + [(d.name, d.features) for d in spec.demons]:
        if features is not None and features.kind not in ("sensors", "constant", "table"):
            raise ValueError(f"{where}: kind {features.kind!r} codes grid positions; a {spec.world.kind} world "
                             "needs kind = 'sensors' (or 'table', 'constant')")  # fmt: skip


def _field_error(loc: tuple[str | int, ...], kind: str, message: str, value: Any) -> ValidationError:
    """A ValidationError at `loc`, so that the 422 names the field (a model validator's would name the run)."""
    detail = InitErrorDetails(type=PydanticCustomError(kind, message), loc=loc, input=value)
    return ValidationError.from_exception_data("RunSpec", [detail])


def weight_count(demon: DemonSpec, spec: RunSpec) -> int:
    """How many primary weights a demon has: its state features, times the actions for GQ's action values."""
    features = demon.features or spec.features
    return features.state_size() * (spec.world.num_actions() if demon.learner == "gq" else 1)


def _check_demon_features(spec: RunSpec) -> None:
    """Table features read a known discrete sensor within the table; initial weights fit the demon; no
    adaptive step size on features of value 2 (repeated table indices).

    Raises:
        ValidationError: naming the field (demons.<i>.initial_weights, demons.<i>.step_size, features.table).
    """
    sensors = spec.world.sensor_names()
    bounds = spec.world.sensor_bounds()
    for where, features in [(("features",), spec.features)] + [
        (("demons", i, "features"), d.features) for i, d in enumerate(spec.demons)
    ]:
        if features is None or features.kind != "table":
            continue
        if features.sensor not in sensors:
            raise _field_error((*where, "sensor"), "table_sensor", f"table features read unknown sensor "
                               f"{features.sensor!r} (known: {', '.join(sensors)})", features.sensor)  # fmt: skip
        low, high = bounds.get(features.sensor or "", (-math.inf, math.inf))
        rows = len(features.table or [])
        if (math.isfinite(low) and round(low) < 0) or (math.isfinite(high) and round(high) > rows - 1):
            raise _field_error((*where, "table"), "table_rows", f"sensor {features.sensor!r} reads {low:g} to "
                               f"{high:g}; the table has a row for each of 0 to {rows - 1} only", rows)  # fmt: skip
    for i, demon in enumerate(spec.demons):
        features = demon.features or spec.features
        if features.has_repeats():
            mode, _ = demon_step_size(demon, spec.learning)
            if mode != "constant":
                why = (f"demon {demon.name!r}: step size {mode!r} is not defined on features of value 2 (a table row "
                       "lists an index twice): Autostep's normaliser and TIDBD's h decay take each feature's value "
                       "squared, which a repeated index does not give; use 'constant'")  # fmt: skip
                raise _field_error(("demons", i, "step_size"), "repeated_indices", why, mode)
        if demon.initial_weights is not None:
            n = weight_count(demon, spec)
            if len(demon.initial_weights) != n:
                raise _field_error(("demons", i, "initial_weights"), "initial_weights", f"demon {demon.name!r} has "
                                   f"{n} weights; initial_weights lists {len(demon.initial_weights)}",
                                   len(demon.initial_weights))  # fmt: skip


def topological_order(deps: dict[str, set[str]]) -> list[str]:
    """Order names so that every name comes after the names it depends on.

    Iterative (Kahn's algorithm), so a chain of any length within the limits orders without recursion;
    ties are broken by name, so the order is the same for the same graph.

    Raises:
        ValueError: naming the demons of a cycle.
    """
    waiting = {name: len(deps[name]) for name in deps}  # dependencies not yet ordered
    readers: dict[str, list[str]] = {name: [] for name in deps}
    for name in deps:
        for dep in deps[name]:
            readers[dep].append(name)
    ready = sorted(name for name, count in waiting.items() if count == 0)
    heapq.heapify(ready)
    order: list[str] = []
    while ready:
        name = heapq.heappop(ready)
        order.append(name)
        for reader in readers[name]:
            waiting[reader] -= 1
            if waiting[reader] == 0:
                heapq.heappush(ready, reader)
    if len(order) < len(deps):
        raise ValueError(f"demons depend on each other in a cycle: {' -> '.join(_cycle(deps, set(order)))}")
    return order


def _cycle(deps: dict[str, set[str]], ordered: set[str]) -> list[str]:
    """One cycle among the names left unordered: follow unordered dependencies until a name repeats."""
    name = min(n for n in deps if n not in ordered)
    path: list[str] = []
    seen: dict[str, int] = {}
    while name not in seen:
        seen[name] = len(path)
        path.append(name)
        name = min(d for d in deps[name] if d not in ordered)
    return [*path[seen[name] :], name]
