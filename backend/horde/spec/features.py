"""State features (DESIGN section 3): which kind codes a state, and its sizes.

Features are sparse, each active one with a value. The kinds: `stripes`, `tiles`, `grid`, `constant`
(positions on the grid world, binary); `sensors` (each sensor tiled over its range and hashed, binary);
`table` (a row of active indices per reading of a discrete sensor, with values); bases over named sensors
scaled from their ranges to [0, 1]: `polynomial` and `fourier` (Sutton & Barto 2018, section 9.5),
`rbf` (radial basis functions on a grid of centres) and `linear` (the sensors themselves, plus a bias).
Optional `condition`: the features copied into blocks, one selected by another demon's prediction.
"""

from __future__ import annotations

import itertools
from typing import Annotated, Literal

from pydantic import Field, ValidationInfo, field_validator, model_validator

from horde.spec.base import MAX_FEATURES, Finite, Model, Name, SensorName, field_error

MAX_TABLE_VALUES = 4096  # readings of a table's discrete sensor


class Condition(Model):
    demon: Name
    thresholds: list[Finite] = Field(min_length=1, max_length=15)

    @field_validator("thresholds")
    @classmethod
    def _sorted(cls, thresholds: list[float]) -> list[float]:
        if any(b <= a for a, b in itertools.pairwise(thresholds)):
            raise ValueError("thresholds must be strictly increasing")
        return thresholds


class Aggregate(Model):
    """State aggregation (Sutton & Barto 2018, section 9.3) as a table: the readings first..last of the table's
    sensor in groups of `size` consecutive ones, one feature per group (readings outside: the nearest group)."""

    first: int = Field(ge=0, lt=MAX_TABLE_VALUES, description="the first reading of the first group")
    last: int = Field(ge=0, lt=MAX_TABLE_VALUES, description="the last reading of the last group")
    size: int = Field(ge=1, lt=MAX_TABLE_VALUES, description="readings per group")

    @model_validator(mode="after")
    def _ordered(self) -> Aggregate:
        if self.last < self.first:
            raise ValueError("last must not be below first")
        return self

    def table(self) -> list[list[int]]:
        """One row per reading 0..last + 1: its group's index."""
        groups = -(-(self.last - self.first + 1) // self.size)
        return [[min(max((r - self.first) // self.size, 0), groups - 1)] for r in range(self.last + 2)]


class TiledSensor(Model):
    """One sensor that features read (tiled by `sensors`, the input of a basis): its readings in [low, high] are
    scaled to [0, 1] (and clipped). A range left out is the world's (`horde.spec.run.check_world_fit` refuses a
    sensor without one)."""

    sensor: str = Field(min_length=1, max_length=80, description="a sensor name, e.g. in:zone3")
    low: Finite | None = Field(default=None, description="the lowest reading resolved (default: the world's range)")
    high: Finite | None = Field(default=None, description="the highest reading resolved (default: the world's range)")

    @model_validator(mode="after")
    def _ordered(self) -> TiledSensor:
        if self.low is not None and self.high is not None and not self.low < self.high:
            raise ValueError(f"sensor {self.sensor!r}: low must be below high")
        return self


MAX_TILED_SENSORS = 256
MAX_TABLE_ACTIVE = 64  # indices listed per reading
MAX_ORDER = 32  # polynomial and Fourier bases
MAX_CENTRES = 64  # radial basis functions per sensor
MAX_BASIS_FEATURES = 10_000  # features of a polynomial, Fourier or RBF basis (all active in every state)
BINARY_KINDS = ("stripes", "tiles", "grid", "constant", "sensors")
BASIS_KINDS = ("polynomial", "fourier", "rbf", "linear")  # real-valued features over named sensors
SENSOR_KINDS = ("sensors", *BASIS_KINDS)  # the kinds that read `sensors` (with their ranges)
FeatureIndex = Annotated[int, Field(ge=0, lt=MAX_FEATURES)]
TableRow = Annotated[list[FeatureIndex], Field(min_length=1, max_length=MAX_TABLE_ACTIVE)]
ValueRow = Annotated[list[Finite], Field(min_length=1, max_length=MAX_TABLE_ACTIVE)]
FeatureKind = Literal["stripes", "tiles", "grid", "constant", "sensors", "table", "polynomial", "fourier", "rbf",
                      "linear"]  # fmt: skip


class FeatureSpec(Model):
    """How a state is coded into sparse features, each with a value (DESIGN section 3)."""

    kind: FeatureKind = "stripes"
    parts: int = Field(default=5, ge=1, le=1000, description="stripes: columns, rows, diagonals")
    tilings: int = Field(default=8, ge=1, le=64, description="tiles, sensors: number of offset tilings")
    tiles: int = Field(default=8, ge=1, le=1000, description="tiles, grid, sensors: tiles per dimension")
    sensors: list[TiledSensor] | None = Field(
        default=None,
        max_length=MAX_TILED_SENSORS,
        description="sensors: each tiled on its own; polynomial, fourier, rbf, linear: the basis' inputs, each "
        "scaled from its range [low, high] to [0, 1]",
    )
    size: int | None = Field(
        default=None,
        ge=1,
        le=MAX_FEATURES - 1,
        description="sensors: the hash table's size (features besides the bias)",
    )
    order: int | None = Field(
        default=None, ge=0, le=MAX_ORDER, description="polynomial, fourier: the highest exponent (or frequency) "
        "of each input: (order + 1)^inputs features",
    )  # fmt: skip
    centres: int | None = Field(
        default=None, ge=1, le=MAX_CENTRES, description="rbf: radial basis functions per input, evenly spaced "
        "over [0, 1]: centres^inputs features",
    )  # fmt: skip
    width: Annotated[float, Field(gt=0.0, le=100.0, allow_inf_nan=False)] | None = Field(
        default=None, description="rbf: sigma of each Gaussian, in units of the scaled inputs (default: the "
        "spacing of the centres)",
    )  # fmt: skip
    sensor: SensorName | None = Field(
        default=None, description="table: the discrete sensor whose reading (0, 1, 2, ...) picks a row of the table"
    )
    table: list[TableRow] | None = Field(
        default=None,
        max_length=MAX_TABLE_VALUES,
        description="table: per reading of the sensor, its active feature indices (all rows of one length); an "
        "index listed twice is a feature of value 2 there (Baird's counterexample)",
    )
    values: list[ValueRow] | None = Field(
        default=None,
        max_length=MAX_TABLE_VALUES,
        description="table: the value of each index listed, row by row (default 1): Boyan's chain, Sutton et "
        "al. 2009's inverted and dependent features",
    )
    aggregate: Aggregate | None = Field(
        default=None, description="table: state aggregation, written for the table (which is then made from it)"
    )
    condition: Condition | None = None

    @model_validator(mode="before")
    @classmethod
    def _aggregated(cls, data: object) -> object:
        """A table with `aggregate` gets its rows from it (a dump's table is made again, the same)."""
        if isinstance(data, dict) and data.get("kind") == "table" and isinstance(data.get("aggregate"), dict):
            try:
                table = Aggregate.model_validate(data["aggregate"]).table()
            except ValueError:
                return data  # the field's own validation names the problem
            return {**data, "table": table, "values": None}
        return data

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
        if self.kind in SENSOR_KINDS and not self.sensors:
            raise ValueError(f"{self.kind} features need a list of sensors (each with its range [low, high], or "
                             "the world's)")  # fmt: skip
        if self.kind not in SENSOR_KINDS and self.sensors is not None:
            raise ValueError(f"sensors belong to kinds {', '.join(SENSOR_KINDS)}")
        if (self.kind == "sensors") != (self.size is not None):
            raise ValueError("sensors features need a hash table size; size belongs to kind = 'sensors' only")
        if (self.kind in ("polynomial", "fourier")) != (self.order is not None):
            raise ValueError("polynomial and fourier features need an order; order belongs to them only")
        if (self.kind == "rbf") != (self.centres is not None) or (self.width is not None and self.kind != "rbf"):
            raise ValueError("rbf features need centres (and may set width); centres and width belong to rbf only")
        self._check_table()
        if self.kind in ("polynomial", "fourier", "rbf") and self.base_size() > MAX_BASIS_FEATURES:
            field = "centres" if self.kind == "rbf" else "order"
            raise field_error("FeatureSpec", (field,), "basis_size", f"a {self.kind} basis of {getattr(self, field)}"
                              f" over {len(self.sensors or [])} inputs has {self.base_size()} features, more than "
                              f"{MAX_BASIS_FEATURES}", getattr(self, field))  # fmt: skip
        if self.state_size() > MAX_FEATURES:
            raise ValueError(f"at most {MAX_FEATURES} state features (this spec has {self.state_size()})")
        return self

    def _check_table(self) -> None:
        if self.kind != "table":
            if self.sensor is not None or self.table is not None or self.values is not None or self.aggregate:
                raise ValueError("sensor, table, values and aggregate belong to kind = 'table' features")
            return
        if self.sensor is None or not self.table:
            raise ValueError("table features need a sensor and a table: one row of active indices per reading")
        lengths = sorted({len(row) for row in self.table})
        if len(lengths) > 1:
            raise ValueError(f"every row of the table lists the same number of indices (found {lengths})")
        if self.values is not None and [len(row) for row in self.values] != [len(row) for row in self.table]:
            raise field_error("FeatureSpec", ("values",), "table_values", "values must have one value per index of "
                              "the table, row by row (the same shape)", len(self.values))  # fmt: skip

    def base_size(self) -> int:
        """Number of state features before conditioning."""
        inputs = len(self.sensors or [])
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
        if self.kind in ("polynomial", "fourier"):
            return int((self.order or 0) + 1) ** inputs
        if self.kind == "rbf":
            return int(self.centres or 1) ** inputs
        if self.kind == "linear":
            return inputs + 1
        return 1

    @property
    def binary(self) -> bool:
        """Whether every active feature has the value 1 in every state (the engine's fast special case)."""
        if self.kind in BINARY_KINDS:
            return True
        if self.kind == "table":
            return not self.has_repeats() and all(v == 1.0 for row in self.values or [] for v in row)
        return False

    def has_repeats(self) -> bool:
        """Whether a row of a table lists an index more than once (their values add up)."""
        return any(len(set(row)) < len(row) for row in self.table or [])

    def active_count(self) -> int:
        """Number of active state features (indices listed, for a table), the same in every state: a constant
        step size alpha is divided by it (DESIGN section 5)."""
        if self.kind == "sensors":
            return self.tilings * len(self.sensors or []) + 1
        if self.kind == "table":
            return len((self.table or [[0]])[0])
        if self.kind in BASIS_KINDS:
            return self.base_size()
        return {"stripes": 5, "tiles": self.tilings + 1, "grid": 1, "constant": 1}[self.kind]

    def state_size(self) -> int:
        blocks = len(self.condition.thresholds) + 1 if self.condition else 1
        return self.base_size() * blocks
