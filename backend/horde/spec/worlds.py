"""World kinds (DESIGN section 2): the grid world, a Gymnasium environment, a live stream of observations.

Each keeps the grid world's contract: named sensors with ranges, a number of actions, terminated apart
from truncated. `world.kind` tells them apart; a world without `kind` is the grid world.

A Gymnasium world's sensors are the environment's: validating its spec makes no environment. They are
resolved in `horde.worlds` (`horde.worlds.gym_spaces.resolve_world`), which makes the environment once and
hands the spec its sensors and actions; until then `sensor_names()` and the checks that read sensors wait.
"""

from __future__ import annotations

import itertools
import math
from typing import Annotated, Any, Literal

from pydantic import Discriminator, Field, PrivateAttr, Tag, ValidationError, field_validator, model_validator
from pydantic_core import InitErrorDetails, PydanticCustomError

from horde.spec.base import MAX_ACTIONS as MAX_ACTIONS
from horde.spec.base import (
    MAX_COLORS,
    MAX_REGIONS,
    MAX_SENSORS,
    MAX_STEPS,
    MAX_WORLD_SIZE,
    Finite,
    Model,
    Name,
    PositiveSize,
    Probability,
    SensorName,
)

ACTIONS: tuple[str, ...] = ("up", "down", "left", "right")
# What a start rectangle whose every point lies in an obstacle or a terminal is told, by the spec (a 422 at
# `world.start`) and by both engines (horde.core.world.ImpossibleStartError) if an unvalidated spec reaches them.
IMPOSSIBLE_START = "the start rectangle has no cell outside obstacles and terminals"

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

    @property
    def resolved(self) -> bool:
        """The grid world's sensors are its spec's (always known)."""
        return True

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

    @property
    def resolved(self) -> bool:
        """A stream's sensors are written in its spec (always known)."""
        return True

    def sensor_names(self) -> list[str]:
        return [s.name for s in self.sensors]

    def sensor_bounds(self) -> dict[str, tuple[float, float]]:
        return _sensor_bounds(self.sensors)

    def num_actions(self) -> int:
        return self.actions


class UnresolvedWorldError(ValueError):
    """A Gymnasium world's sensors were asked for before `horde.worlds` resolved them."""


class GymnasiumWorldSpec(Model):
    """An installed Gymnasium environment with a `Box` (or `Discrete`) observation and a `Discrete` action space.

    Its sensors are the observation's components (named and ranged by `horde.worlds.gym_spaces`), then
    `reward`, `terminated` and `truncated`, read after every step (0 at an episode's first state). They are
    resolved outside validation (`horde.worlds.gym_spaces.resolve_world`): `resolved` says whether they are.
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
    _sensors: list[SensorRange] | None = PrivateAttr(default=None)
    _actions: int = PrivateAttr(default=0)

    def __eq__(self, other: object) -> bool:
        """Equal fields: whether the sensors are resolved yet is not part of the spec (they follow from `id`)."""
        if not isinstance(other, GymnasiumWorldSpec):
            return NotImplemented
        return self.model_dump() == other.model_dump()

    def __hash__(self) -> int:
        return hash((self.kind, self.name, self.id, self.max_steps))

    @property
    def resolved(self) -> bool:
        """Whether the environment's sensors and actions are known (`horde.worlds.gym_spaces.resolve_world`)."""
        return self._sensors is not None

    def with_sensors(self, sensors: list[SensorRange], actions: int) -> GymnasiumWorldSpec:
        """A copy of this spec whose sensors and number of actions are resolved (by `horde.worlds`)."""
        copy = self.model_copy()
        copy._sensors = list(sensors)
        copy._actions = int(actions)
        return copy

    def _known(self) -> list[SensorRange]:
        if self._sensors is None:
            raise UnresolvedWorldError(
                f"the sensors of Gymnasium world {self.id!r} are not resolved yet: "
                "horde.worlds.gym_spaces.resolve_world(spec) resolves them"
            )
        return self._sensors

    def sensor_ranges(self) -> list[SensorRange]:
        """The observation's components with their ranges, then reward, terminated and truncated."""
        return list(self._known())

    def sensor_names(self) -> list[str]:
        return [s.name for s in self._known()]

    def sensor_bounds(self) -> dict[str, tuple[float, float]]:
        return _sensor_bounds(self._known())

    def num_actions(self) -> int:
        self._known()
        return self._actions


WORLD_KINDS = ("grid", "gymnasium", "stream")


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
