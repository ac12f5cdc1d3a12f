"""Tile coders (DESIGN section 3): property tests for every kind, and indices computed by hand."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from horde.core import reference
from horde.core.features import StateCoder, all_action_indices, state_action_indices
from horde.spec import Condition, FeatureSpec, RunSpec

sizes = st.floats(min_value=1.0, max_value=1000.0, allow_nan=False)
unit = st.floats(min_value=0.0, max_value=1.0, exclude_max=True, allow_nan=False)

feature_specs = st.one_of(
    st.builds(FeatureSpec, kind=st.just("stripes"), parts=st.integers(1, 30)),
    st.builds(FeatureSpec, kind=st.just("tiles"), tilings=st.integers(1, 16), tiles=st.integers(1, 20)),
    st.builds(FeatureSpec, kind=st.just("grid"), tiles=st.integers(1, 30)),
    st.builds(FeatureSpec, kind=st.just("constant")),
)


def points(width: float, height: float, us: list[float], vs: list[float]) -> tuple[np.ndarray, np.ndarray]:
    x = np.minimum(np.array(us) * width, np.nextafter(width, 0))
    y = np.minimum(np.array(vs) * height, np.nextafter(height, 0))
    return x, y


@given(spec=feature_specs, width=sizes, height=sizes, us=st.lists(unit, min_size=1, max_size=8), data=st.data())
def test_exactly_k_distinct_indices_in_range(spec, width, height, us, data):
    vs = data.draw(st.lists(unit, min_size=len(us), max_size=len(us)))
    coder = StateCoder(spec, width, height)
    x, y = points(width, height, us, vs)
    idx = coder.active(x, y)
    assert idx.shape == (len(us), spec.active_count())
    assert coder.k == spec.active_count()
    assert coder.n == spec.state_size()
    assert idx.dtype == np.int64
    assert (idx >= 0).all() and (idx < coder.n).all()
    for row in idx:
        assert len(set(row.tolist())) == coder.k


@given(spec=feature_specs, width=sizes, height=sizes, u=unit, v=unit)
def test_coder_equals_the_plain_reference(spec, width, height, u, v):
    coder = StateCoder(spec, width, height)
    x, y = points(width, height, [u], [v])
    dense = reference.state_features(spec, float(x[0]), float(y[0]), width, height, 0.0)
    assert sorted(coder.active(x, y)[0].tolist()) == np.flatnonzero(dense).tolist()


@given(
    tilings=st.integers(1, 16),
    tiles=st.integers(1, 20),
    u=st.floats(0.0, 0.999),
    v=st.floats(0.0, 0.999),
    du=st.floats(-1.0, 1.0),
    dv=st.floats(-1.0, 1.0),
)
def test_near_points_share_tiles(tilings, tiles, u, v, du, dv):
    """Closer than 1/tilings of a tile in each coordinate: at most one tiling per boundary family differs.

    Tiling t is offset by t/T of a tile in x, so the x boundaries of all tilings are 1/T apart and a
    move shorter than that crosses at most one. In y the offsets are 3t/T mod 1: also 1/T apart unless 3
    divides T, when three tilings share each boundary.
    """
    spec = FeatureSpec(kind="tiles", tilings=tilings, tiles=tiles)
    coder = StateCoder(spec, 500.0, 500.0)
    reach = 0.999 / (tilings * tiles)  # less than 1/T of a tile, in units of the world
    u2 = min(max(u + du * reach, 0.0), 0.999)
    v2 = min(max(v + dv * reach, 0.0), 0.999)
    a, b = coder.active(np.array([u, u2]) * 500, np.array([v, v2]) * 500)
    shared = len(set(a.tolist()) & set(b.tolist()))
    y_family = 3 if tilings % 3 == 0 else 1
    assert shared >= coder.k - 1 - y_family
    assert coder.n - 1 in set(a.tolist()) & set(b.tolist())  # the bias is always shared
    if du == 0 and dv == 0:
        assert shared == coder.k


@given(tilings=st.integers(1, 16), tiles=st.integers(1, 20), u=st.floats(0, 0.999), v=st.floats(0, 0.999))
def test_points_a_tile_apart_share_only_the_bias(tilings, tiles, u, v):
    spec = FeatureSpec(kind="tiles", tilings=tilings, tiles=tiles)
    coder = StateCoder(spec, 500.0, 500.0)
    apart = 1.001 / tiles  # a little more than a tile, so that rounding cannot bring them into one
    u2 = u + apart if u + apart < 1 else u - apart
    if not 0 <= u2 < 1:
        return  # too few tiles: there is no point that far away
    a, b = coder.active(np.array([u, u2]) * 500, np.array([v, v]) * 500)
    assert set(a.tolist()) & set(b.tolist()) == {coder.n - 1}


def test_stripes_for_five_parts_has_29_features_and_the_hand_computed_indices():
    spec = FeatureSpec(kind="stripes", parts=5)
    coder = StateCoder(spec, 500, 500)
    assert coder.n == 29 and coder.k == 5
    # columns 0-4, rows 5-9, diagonals (i + j) 10-18, anti-diagonals (i - j + 4) 19-27, bias 28.
    xs = np.array([0.0, 450.0, 120.0, 499.9, 250.0])
    ys = np.array([0.0, 150.0, 480.0, 499.9, 250.0])
    expected = [
        [0, 5, 10, 23, 28],  # cell (0, 0): diagonal 0, anti-diagonal 0 - 0 + 4
        [4, 6, 15, 26, 28],  # cell (4, 1): diagonal 5, anti-diagonal 4 - 1 + 4 = 7
        [1, 9, 15, 20, 28],  # cell (1, 4): diagonal 5, anti-diagonal 1 - 4 + 4 = 1
        [4, 9, 18, 23, 28],  # cell (4, 4): diagonal 8, anti-diagonal 4
        [2, 7, 14, 23, 28],  # cell (2, 2): diagonal 4, anti-diagonal 4
    ]
    assert coder.active(xs, ys).tolist() == expected


def test_stripes_points_in_one_cell_share_everything_and_a_column_shares_column_and_bias():
    coder = StateCoder(FeatureSpec(kind="stripes", parts=5), 500, 500)
    a, b, c = coder.active(np.array([210.0, 299.0, 250.0]), np.array([10.0, 99.0, 450.0]))
    assert set(a) == set(b)
    assert set(a) & set(c) == {2, 28}


def test_tiles_are_offset_asymmetrically_by_hand():
    # 4 tilings of (2 + 1) x (2 + 1) tiles: n = 4 * 9 + 1 = 37. Offsets (t/4, 3t/4 mod 1) of a tile:
    # t=0 (0, 0), t=1 (0.25, 0.75), t=2 (0.5, 0.5), t=3 (0.75, 0.25).
    coder = StateCoder(FeatureSpec(kind="tiles", tilings=4, tiles=2), 500, 500)
    assert coder.n == 37 and coder.k == 5
    # (200, 150): u * tiles = 0.8, v * tiles = 0.6.
    #   t=0: (0.80, 0.60) -> tile (0, 0) -> 0
    #   t=1: (1.05, 1.35) -> tile (1, 1) -> 9 + 3 + 1 = 13
    #   t=2: (1.30, 1.10) -> tile (1, 1) -> 18 + 3 + 1 = 22
    #   t=3: (1.55, 0.85) -> tile (1, 0) -> 27 + 3 + 0 = 30
    out = coder.active(np.array([0.0, 200.0]), np.array([0.0, 150.0]))
    assert out.tolist() == [[0, 9, 18, 27, 36], [0, 13, 22, 30, 36]]


def test_grid_is_one_aligned_tiling():
    coder = StateCoder(FeatureSpec(kind="grid", tiles=5), 500, 500)
    assert coder.n == 25 and coder.k == 1
    assert coder.active(np.array([250.0, 0.0, 499.0]), np.array([50.0, 0.0, 499.0])).tolist() == [
        [10],
        [0],
        [24],
    ]
    gx, gy = np.meshgrid(np.arange(0, 500, 100.0) + 50, np.arange(0, 500, 100.0) + 50)
    cells = coder.active(gx.ravel(), gy.ravel())[:, 0]
    assert sorted(cells.tolist()) == list(range(25))  # tabular: one feature per cell
    # anywhere inside a cell gives that cell's feature
    assert coder.active(np.array([200.0, 299.99]), np.array([300.0, 399.99]))[:, 0].tolist() == [13, 13]


def test_constant_is_one_feature_always_on():
    coder = StateCoder(FeatureSpec(kind="constant"), 500, 500)
    assert coder.n == 1 and coder.k == 1
    assert coder.active(np.array([0.0, 123.0, 499.0]), np.array([0.0, 456.0, 1.0])).tolist() == [
        [0],
        [0],
        [0],
    ]


def test_condition_blocks_select_by_threshold():
    spec = FeatureSpec(kind="stripes", parts=5, condition=Condition(demon="lamp", thresholds=[-0.5, 0.5]))
    coder = StateCoder(spec, 500, 500)
    assert coder.base_n == 29 and coder.n == 87 and coder.k == 5
    base = [0, 5, 10, 23, 28]
    condition = np.array([-1.0, -0.5, 0.0, 0.49, 0.5, 3.0])
    idx = coder.active(np.zeros(6), np.zeros(6), condition)
    # below the first threshold: block 0; a prediction equal to a threshold selects the block above it
    blocks = [0, 1, 1, 1, 2, 2]
    assert idx.tolist() == [[i + 29 * b for i in base] for b in blocks]
    assert coder.block_of(condition).tolist() == blocks
    with pytest.raises(ValueError, match="condition"):
        coder.active(np.zeros(1), np.zeros(1))


@given(
    thresholds=st.lists(st.floats(-100, 100), min_size=1, max_size=6, unique=True).map(sorted),
    condition=st.floats(-200, 200),
    u=unit,
    v=unit,
)
def test_condition_block_is_the_number_of_thresholds_reached(thresholds, condition, u, v):
    spec = FeatureSpec(kind="tiles", tilings=3, tiles=4, condition=Condition(demon="c", thresholds=thresholds))
    coder = StateCoder(spec, 500, 500)
    x, y = np.array([u * 500]), np.array([v * 500])
    block = sum(condition >= t for t in thresholds)
    plain = StateCoder(FeatureSpec(kind="tiles", tilings=3, tiles=4), 500, 500).active(x, y)
    out = coder.active(x, y, np.array([condition]))
    assert out.tolist() == (plain + block * coder.base_n).tolist()
    dense = reference.state_features(spec, float(x[0]), float(y[0]), 500, 500, condition)
    assert sorted(out[0].tolist()) == np.flatnonzero(dense).tolist()


def test_state_action_features_put_the_state_features_in_the_action_block():
    state_idx = np.array([[0, 5, 10, 23, 28], [1, 9, 15, 20, 28]])
    out = state_action_indices(state_idx, np.array([0, 3]), 29)
    assert out.tolist() == [[0, 5, 10, 23, 28], [88, 96, 102, 107, 115]]
    every = all_action_indices(state_idx, 29, 4)
    assert every.shape == (2, 4, 5)
    for a in range(4):
        assert every[:, a].tolist() == (state_idx + 29 * a).tolist()


@given(parts=st.integers(1, 50))
def test_stripes_size_formula(parts):
    spec = FeatureSpec(kind="stripes", parts=parts)
    assert StateCoder(spec, 1, 1).n == 2 * parts + 2 * (2 * parts - 1) + 1 == 6 * parts - 1
    assert math.isclose(spec.base_size(), 6 * parts - 1)


# ----------------------------------------------------------------------------------------------
# Features tiled over any sensors, hashed into a fixed table (kind "sensors")

SENSOR_NAMES = ["a", "b", "c", "d"]


@st.composite
def sensor_specs(draw):
    count = draw(st.integers(1, 4))
    tilings = draw(st.integers(1, 8))
    lows = draw(st.lists(st.floats(-100, 100), min_size=count, max_size=count))
    sensors = [
        {"sensor": SENSOR_NAMES[i], "low": low, "high": low + draw(st.floats(0.5, 50))} for i, low in enumerate(lows)
    ]
    size = draw(st.integers(tilings * count, tilings * count + 40))  # small tables: hashes collide
    return FeatureSpec.model_validate(
        {"kind": "sensors", "tilings": tilings, "tiles": draw(st.integers(1, 12)), "size": size, "sensors": sensors}
    )


READINGS = st.lists(st.floats(-200, 200), min_size=4, max_size=4)


@given(spec=sensor_specs(), batch=st.lists(READINGS, min_size=1, max_size=3))
def test_hashed_sensor_tiles_equal_the_plain_reference(spec, batch):
    """Every state of a batch coded as the reference codes it alone: the coder's marks of the entries taken
    (read off in order where the table is small beside the count squared, else sorted) start each state
    clear."""
    coder = StateCoder(spec, 500, 500, SENSOR_NAMES)
    active = coder.active(np.zeros(len(batch)), np.zeros(len(batch)), sensors=np.array(batch))
    for idx, readings in zip(active, batch, strict=True):
        assert len(idx) == spec.active_count() == len(set(idx.tolist())), "k distinct features, collisions probed"
        assert idx.tolist() == sorted(idx.tolist()) and idx[-1] == spec.size, "sorted, the bias last"
        dense = reference.state_features(spec, 0.0, 0.0, 500, 500, 0.0, dict(zip(SENSOR_NAMES, readings, strict=True)))
        assert idx.tolist() == np.flatnonzero(dense).tolist()


def test_hashed_sensor_tiles_by_hand():
    """One sensor in [0, 10], 2 tilings of 4 tiles, a table of 8: reading 5 is u = 0.5.

    tiling 0: tile floor(2.0 + 0) = 2, key (0 * 2 + 0) * 5 + 2 = 2, hash 2 * 2654435761 mod 2^32 mod 8 = 2
    tiling 1: tile floor(2.0 + 0.5) = 2, key (0 * 2 + 1) * 5 + 2 = 7, 7 * 2654435761 mod 2^32 = 1401181143,
              mod 8 = 7
    """
    spec = FeatureSpec.model_validate(
        {"kind": "sensors", "tilings": 2, "tiles": 4, "size": 8, "sensors": [{"sensor": "a", "low": 0, "high": 10}]}
    )
    coder = StateCoder(spec, 500, 500, SENSOR_NAMES)
    assert (7 * 2654435761) % 2**32 == 1401181143
    assert coder.active(np.zeros(1), np.zeros(1), sensors=np.array([[5.0, 0, 0, 0]]))[0].tolist() == [2, 7, 8]


@pytest.mark.parametrize(
    ("change", "field"),
    [
        ({"size": 1}, ("features", "size")),
        ({"sensors": [{"sensor": "a", "low": 0}]}, ("features", "sensors", 0, "high")),  # the world gives none
        ({"sensors": [{"sensor": "a", "high": 1}]}, ("features", "sensors", 0, "low")),
        ({"sensors": [{"sensor": "a", "low": 1, "high": 1}]}, ("features", "sensors", 0)),
    ],
)
def test_bad_tiled_sensors_name_the_field(change, field):
    """A range left out is the world's: a stream sensor without one is refused where the range is missing."""
    body = {"kind": "sensors", "tilings": 2, "tiles": 4, "size": 8, "sensors": [{"sensor": "a", "low": 0, "high": 1}]}
    world = {"kind": "stream", "actions": 2, "sensors": [{"name": "a"}]}
    with pytest.raises(ValueError) as info:
        RunSpec.model_validate({"world": world, "features": {**body, **change}})
    assert info.value.errors()[0]["loc"] == field  # type: ignore[attr-defined]


def test_a_range_left_out_is_the_worlds() -> None:
    world = {"kind": "stream", "actions": 2, "sensors": [{"name": "a", "low": -2, "high": 6}]}
    spec = RunSpec.model_validate({"world": world, "features": {"kind": "sensors", "tilings": 2, "tiles": 4,
                                                                "size": 8, "sensors": [{"sensor": "a"}]}})  # fmt: skip
    coder = StateCoder(spec.features, 1, 1, ["a"], spec.world.sensor_bounds())
    assert coder.entry.ranges == [(-2.0, 6.0)]
    # a reading of 2 is u = 0.5 of [-2, 6], the same tiles as 5 of [0, 10] (test_hashed_sensor_tiles_by_hand)
    assert coder.active(np.zeros(1), np.zeros(1), sensors=np.array([[2.0]]))[0].tolist() == [2, 7, 8]
