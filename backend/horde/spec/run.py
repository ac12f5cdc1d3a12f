"""The run: a world, its features, a behaviour, demons, learning defaults and a protocol, checked as a whole.

A run's cross-field checks live here: names and references of the demon graph (`check_demon_graph`), and
what needs the world's sensors and actions (`check_world_fit`: expressions reading known sensors,
continuations within [0, 1], policies over the world's actions, features the world can code). A Gymnasium
world's sensors are resolved outside validation (`horde.worlds.gym_spaces.resolve_world`), which runs
`check_world_fit` once they are known.
"""

from __future__ import annotations

import math
from typing import Any

from pydantic import Field, ValidationError, ValidationInfo, field_validator, model_validator
from pydantic_core import InitErrorDetails, PydanticCustomError

from horde.spec.base import MAX_DEMONS, MAX_FEATURES, Model, Name, error_detail, field_error
from horde.spec.demons import DemonSpec, LearningSpec
from horde.spec.expressions import expr_interval, expr_sensors
from horde.spec.families import MAX_FAMILIES, DemonFamily
from horde.spec.features import SENSOR_KINDS, FeatureSpec
from horde.spec.graph import demon_dependencies, topological_order
from horde.spec.policies import OWN_VALUE_POLICIES, BehaviourSpec
from horde.spec.protocol import ProtocolSpec, ThesisResults
from horde.spec.worlds import WORLD_KINDS, AnyWorldSpec, WorldSpec


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
                details.append(error_detail(e, loc))
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
        if self.world.resolved:  # a Gymnasium world's are checked when horde.worlds resolves its sensors
            check_world_fit(self)
        return self


def check_demon_graph(spec: RunSpec) -> list[str]:
    """Validate the demons' names and references; return the demons in dependency order.

    What needs the world's sensors and actions is `check_world_fit`'s.

    Raises:
        ValueError: a repeated name, a reference to an unknown demon, a demon followed that has no policy, a
            behaviour acting on a demon without action values, or a cycle.
    """
    by_name: dict[str, DemonSpec] = {}
    for demon in spec.demons:
        if demon.name in by_name:
            raise ValueError(f"demon names must be unique: {demon.name!r} appears twice")
        by_name[demon.name] = demon
    deps: dict[str, set[str]] = {}
    for demon in spec.demons:
        deps[demon.name] = demon_dependencies(demon, spec.features)
        for other in sorted(deps[demon.name]):
            if other not in by_name:
                raise ValueError(f"demon {demon.name!r} refers to unknown demon {other!r}")
        if demon.policy.kind == "of" and demon.policy.demon in by_name:
            followed = by_name[demon.policy.demon]
            if not followed.action_values and followed.policy.kind in OWN_VALUE_POLICIES:
                raise ValueError(f"demon {demon.name!r} follows {followed.name!r}, which has no policy")
    if spec.behaviour.demon is not None:
        control = by_name.get(spec.behaviour.demon)
        if control is None:
            raise ValueError(f"the behaviour refers to unknown demon {spec.behaviour.demon!r}")
        if not control.action_values:
            raise ValueError(f"the behaviour acts on {control.name!r}, which learns no action values")
    test = spec.protocol.test
    if test and test.behaviour.demon is not None and test.behaviour.demon not in by_name:
        raise ValueError(f"the test behaviour refers to unknown demon {test.behaviour.demon!r}")
    return topological_order(deps)


def check_world_fit(spec: RunSpec) -> None:
    """What needs the world's sensors and actions: expressions and features reading known sensors,
    continuations within [0, 1], policies over the world's actions, features the world can code, the
    weights' total, table rows and initial weights.

    Raises:
        ValueError: naming the demon (or behaviour) that does not fit the world.
        ValidationError: naming the field (features.table, a sensor range, demons.<i>.initial_weights).
    """
    sensors = set(spec.world.sensor_names())
    bounds = spec.world.sensor_bounds()
    for demon in spec.demons:
        for field in ("cumulant", "outcome", "continuation"):
            for sensor in sorted(expr_sensors(getattr(demon, field))):
                if sensor not in sensors:
                    raise ValueError(
                        f"demon {demon.name!r}: {field} reads unknown sensor {sensor!r} "
                        f"(known: {', '.join(sorted(sensors))})"
                    )
        low, high = expr_interval(demon.continuation, bounds)
        if math.isfinite(low) and math.isfinite(high) and (low < 0.0 or high > 1.0):
            raise ValueError(
                f"demon {demon.name!r}: continuation can take values in [{low:g}, {high:g}]; it must stay in [0, 1]"
            )
    _check_feature_sensors(spec, sensors, bounds)
    _check_policies(spec)
    total = sum(weight_count(d, spec) for d in spec.demons)
    if total > 50 * MAX_FEATURES:
        raise ValueError(f"the demons' weights would hold {total} numbers, more than {50 * MAX_FEATURES}")
    if not isinstance(spec.world, WorldSpec):
        for where, features in [("features", spec.features)] + [(d.name, d.features) for d in spec.demons]:
            if features is not None and features.kind not in (*SENSOR_KINDS, "constant", "table"):
                raise ValueError(f"{where}: kind {features.kind!r} codes grid positions; a {spec.world.kind} world "
                                 f"needs features over its sensors ({', '.join(SENSOR_KINDS)}, or 'table', "
                                 "'constant')")  # fmt: skip
    _check_demon_features(spec)


def _feature_specs(spec: RunSpec) -> list[tuple[tuple[str | int, ...], FeatureSpec]]:
    """The run's feature specs with where each is written: (loc, spec), the run's first."""
    return [(("features",), spec.features)] + [
        (("demons", i, "features"), d.features) for i, d in enumerate(spec.demons) if d.features is not None
    ]


def _check_feature_sensors(spec: RunSpec, sensors: set[str], bounds: dict[str, tuple[float, float]]) -> None:
    """Features read known sensors, each with a finite range (its own, else the world's).

    Raises:
        ValueError: a sensor the world does not have.
        ValidationError: at `...sensors.<j>.low` (or `high`) for a sensor without a finite range.
    """
    for loc, features in _feature_specs(spec):
        for j, read in enumerate(features.sensors or []):
            if read.sensor not in sensors:
                raise ValueError(f"{'.'.join(map(str, loc))}: reads unknown sensor {read.sensor!r} (known: "
                                 f"{', '.join(sorted(sensors))})")  # fmt: skip
            low, high = sensor_range(read.sensor, read.low, read.high, bounds)
            for end, value in (("low", low), ("high", high)):
                if not math.isfinite(value):
                    why = f"sensor {read.sensor!r} has no {end} bound in this world: give its range [low, high]"
                    raise field_error("RunSpec", (*loc, "sensors", j, end), "sensor_range", why, None)
            if not low < high:
                raise field_error("RunSpec", (*loc, "sensors", j, "high"), "sensor_range", f"sensor {read.sensor!r}"
                                  f": its range [{low:g}, {high:g}] is empty", high)  # fmt: skip


def sensor_range(
    sensor: str, low: float | None, high: float | None, bounds: dict[str, tuple[float, float]]
) -> tuple[float, float]:
    """The range features scale a sensor from: the one given, else the world's."""
    world = bounds.get(sensor, (-math.inf, math.inf))
    return (world[0] if low is None else low), (world[1] if high is None else high)


def _check_policies(spec: RunSpec) -> None:
    """Policies over the world's own actions, sign policies on worlds fed from outside.

    Raises:
        ValueError: naming the demon (or behaviour) whose probabilities or sign rule do not fit the world.
    """
    actions = spec.world.num_actions()
    behaviours = [("the behaviour", spec.behaviour)]
    if spec.protocol.test is not None:
        behaviours.append(("the test behaviour", spec.protocol.test.behaviour))
    for where, policy in [(f"demon {d.name!r}: policy", d.policy) for d in spec.demons] + behaviours:
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


def weight_count(demon: DemonSpec, spec: RunSpec) -> int:
    """How many primary weights a demon has: its state features, times the actions for action values."""
    features = demon.features or spec.features
    return features.state_size() * (spec.world.num_actions() if demon.action_values else 1)


def _check_demon_features(spec: RunSpec) -> None:
    """Table features read a known discrete sensor within the table; initial weights fit the demon.

    Raises:
        ValidationError: naming the field (demons.<i>.initial_weights, features.table).
    """
    sensors = spec.world.sensor_names()
    bounds = spec.world.sensor_bounds()
    for where, features in [(("features",), spec.features)] + [
        (("demons", i, "features"), d.features) for i, d in enumerate(spec.demons)
    ]:
        if features is None or features.kind != "table":
            continue
        if features.sensor not in sensors:
            raise field_error("RunSpec", (*where, "sensor"), "table_sensor", f"table features read unknown sensor "
                              f"{features.sensor!r} (known: {', '.join(sensors)})", features.sensor)  # fmt: skip
        low, high = bounds.get(features.sensor or "", (-math.inf, math.inf))
        rows = len(features.table or [])
        if (math.isfinite(low) and round(low) < 0) or (math.isfinite(high) and round(high) > rows - 1):
            raise field_error("RunSpec", (*where, "table"), "table_rows", f"sensor {features.sensor!r} reads "
                              f"{low:g} to {high:g}; the table has a row for each of 0 to {rows - 1} only",
                              rows)  # fmt: skip
    for i, demon in enumerate(spec.demons):
        if demon.initial_weights is not None:
            n = weight_count(demon, spec)
            if len(demon.initial_weights) != n:
                raise field_error("RunSpec", ("demons", i, "initial_weights"), "initial_weights", f"demon "
                                  f"{demon.name!r} has {n} weights; initial_weights lists "
                                  f"{len(demon.initial_weights)}", len(demon.initial_weights))  # fmt: skip


def validate_world_fit(spec: RunSpec) -> RunSpec:
    """`check_world_fit` outside validation (a Gymnasium world just resolved): its errors as a ValidationError,
    as pydantic would have raised them. Returns the spec.

    Raises:
        ValidationError: the spec does not fit its world.
    """
    try:
        check_world_fit(spec)
    except ValidationError:
        raise
    except ValueError as exc:
        detail = InitErrorDetails(type=PydanticCustomError("value_error", f"Value error, {exc}"), loc=(), input=spec)
        raise ValidationError.from_exception_data("RunSpec", [detail]) from None
    return spec
