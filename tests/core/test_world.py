"""The continuous grid world (DESIGN section 2): moves, walls, termination, colours, slip, noise, sensors."""

from __future__ import annotations

import numpy as np
import pytest

from grids import CRIT, GOAL, PIT, WALL, grid, lamp, lamp_terminal
from horde.core.simulation import Simulation
from horde.core.world import DOWN, LEFT, RIGHT, UP, ImpossibleStartError, World
from horde.spec import IMPOSSIBLE_START, RunSpec, WorldSpec

REGIONS = [
    WALL,
    GOAL,
    lamp_terminal("pit", PIT["rect"], yellow=2.0, purple=-3.0),
    lamp([300, 200, 400, 300], yellow=(1.0, 0.5), purple=(-1.0, 0.5)),
    CRIT | {"rect": [0, 0, 200, 200]},
]


def make_world(**overrides: object) -> World:
    return World(WorldSpec.model_validate(grid(*REGIONS) | overrides))


def at(world: World, points: list[tuple[float, float]], steps: int = 0, color: int = 0):
    """A state of len(points) agents placed by hand."""
    state = world.reset(np.random.default_rng(0), len(points))
    return state._replace(
        x=np.array([p[0] for p in points], dtype=float),
        y=np.array([p[1] for p in points], dtype=float),
        steps=np.full(len(points), steps, dtype=np.int64),
        colors=np.full((len(points), world.num_indicators), color, dtype=np.int64),
    )


def test_each_action_moves_one_step_in_its_direction():
    world = make_world()
    state = at(world, [(200, 100)] * 4)
    nxt, tr = world.step(state, np.array([UP, DOWN, LEFT, RIGHT]), np.random.default_rng(0))
    assert nxt.x.tolist() == [200, 200, 100, 300]
    assert nxt.y.tolist() == [200, 0, 100, 100]
    assert tr.bump.tolist() == [0, 0, 0, 0]
    assert nxt.steps.tolist() == [1, 1, 1, 1]


def test_moving_out_of_the_world_bumps_and_stays():
    world = make_world()
    # left and down from the origin; right from x=400 reaches x=500=width, outside the half-open world.
    state = at(world, [(0, 0), (0, 0), (400, 100), (0, 400)])
    nxt, tr = world.step(state, np.array([LEFT, DOWN, RIGHT, UP]), np.random.default_rng(0))
    assert nxt.x.tolist() == [0, 0, 400, 0]
    assert nxt.y.tolist() == [0, 0, 100, 400]
    assert tr.bump.tolist() == [1, 1, 1, 1]
    assert not tr.terminated.any()
    # a bump still costs a transition
    assert nxt.steps.tolist() == [1, 1, 1, 1]


def test_moving_into_an_obstacle_bumps_and_stays():
    world = make_world()
    # The wall is [100, 200, 200, 300]; (200, 200) is outside it (x1 is exclusive).
    state = at(world, [(100, 100), (0, 200), (200, 200), (200, 100)])
    nxt, tr = world.step(state, np.array([UP, RIGHT, LEFT, UP]), np.random.default_rng(0))
    assert list(zip(nxt.x.tolist(), nxt.y.tolist(), strict=True)) == [
        (100, 100),
        (0, 200),
        (200, 200),
        (200, 200),
    ]
    assert tr.bump.tolist() == [1, 1, 1, 0]


def test_rectangles_are_half_open():
    world = make_world()
    wall = world.region_names.index("wall")
    xs = np.array([100.0, 199.999, 200.0, 150.0, 150.0, 99.999])
    ys = np.array([200.0, 299.999, 250.0, 300.0, 200.0, 250.0])
    inside = world.inside(xs, ys)[:, wall]
    assert inside.tolist() == [True, True, False, False, True, False]
    # The world itself: [0, width) x [0, height).
    blocked = world.blocked(np.array([0.0, 499.9, 500.0, -0.1, 0.0]), np.array([0.0, 0.0, 0.0, 0.0, 500.0]))
    assert blocked.tolist() == [False, False, True, True, True]


def test_terminated_and_truncated_are_kept_apart():
    world = make_world(max_steps=3)
    rng = np.random.default_rng(0)
    # Agent 0 enters the goal on the last allowed step; agent 1 reaches max_steps elsewhere;
    # agent 2 enters the goal early; agent 3 moves without ending anything.
    state = at(world, [(400, 300), (0, 0), (400, 300), (0, 0)])
    state = state._replace(steps=np.array([2, 2, 0, 0]))
    _, tr = world.step(state, np.array([UP, RIGHT, UP, RIGHT]), rng)
    assert tr.terminated.tolist() == [True, False, True, False]
    assert tr.truncated.tolist() == [False, True, False, False]
    assert tr.reward.tolist() == pytest.approx([-0.01 + 1.0, -0.01, -0.01 + 1.0, -0.01])


@pytest.mark.parametrize(("color", "reward"), [(0, 2.0), (1, -3.0)])
def test_terminal_reward_follows_the_indicator_colour(color: int, reward: float):
    world = make_world()
    state = at(world, [(300, 200), (400, 100)], color=color)
    nxt, tr = world.step(state, np.array([RIGHT, UP]), np.random.default_rng(0))
    assert (nxt.x.tolist(), nxt.y.tolist()) == ([400, 400], [200, 200])
    assert tr.terminated.tolist() == [True, True]
    assert tr.reward.tolist() == pytest.approx([-0.01 + reward] * 2)
    assert world.terminal_sign(nxt, tr.inside).tolist() == [np.sign(reward)] * 2


def test_a_custom_transient_reward_is_paid_on_every_transition():
    world = make_world(transient_reward=-0.5)
    state = at(world, [(0, 0), (200, 100), (400, 300)])
    _, tr = world.step(state, np.array([LEFT, RIGHT, UP]), np.random.default_rng(0))
    assert tr.reward.tolist() == pytest.approx([-0.5, -0.5, -0.5 + 1.0])


def test_indicator_colours_are_drawn_with_their_probabilities():
    world = make_world(regions=[lamp([300, 200, 400, 300], red=(1, 0.2), green=(2, 0.5), blue=(3, 0.3))])
    n = 40_000
    colors = world.reset(np.random.default_rng(7), n).colors[:, 0]
    for index, p in enumerate([0.2, 0.5, 0.3]):
        freq = np.mean(colors == index)
        assert abs(freq - p) < 4 * np.sqrt(p * (1 - p) / n), (index, freq)
    # a colour is drawn per episode, so a new reset redraws it
    again = world.reset(np.random.default_rng(8), n).colors[:, 0]
    assert (again != colors).any()


@pytest.mark.parametrize(
    ("action", "expected"),
    [
        (UP, {UP: 0.7, LEFT: 0.15, RIGHT: 0.15, DOWN: 0.0}),
        (RIGHT, {RIGHT: 0.7, UP: 0.15, DOWN: 0.15, LEFT: 0.0}),
    ],
)
def test_slip_goes_to_each_perpendicular_action_half_of_the_time(action: int, expected: dict[int, float]):
    world = make_world(slip=0.3, regions=[])
    n = 40_000
    state = at(world, [(200, 200)] * n)
    nxt, _ = world.step(state, np.full(n, action), np.random.default_rng(3))
    dx, dy = nxt.x - 200, nxt.y - 200
    moved = {UP: (dx == 0) & (dy == 100), DOWN: (dx == 0) & (dy == -100)}
    moved |= {LEFT: (dx == -100) & (dy == 0), RIGHT: (dx == 100) & (dy == 0)}
    assert sum(m.sum() for m in moved.values()) == n
    for a, p in expected.items():
        freq = moved[a].mean()
        assert abs(freq - p) < 4 * np.sqrt(max(p * (1 - p), 1e-12) / n) + 1e-12, (a, freq, p)


def test_noise_adds_gaussian_displacement_with_the_given_std():
    world = make_world(noise=10.0, regions=[])
    n = 20_000
    state = at(world, [(200, 200)] * n)
    nxt, tr = world.step(state, np.full(n, RIGHT), np.random.default_rng(5))
    assert not tr.bump.any()
    dx, dy = nxt.x - 200, nxt.y - 200
    assert dx.mean() == pytest.approx(100, abs=4 * 10 / np.sqrt(n))
    assert dy.mean() == pytest.approx(0, abs=4 * 10 / np.sqrt(n))
    assert dx.std() == pytest.approx(10, rel=0.03)
    assert dy.std() == pytest.approx(10, rel=0.03)


def test_noise_can_push_into_a_wall():
    world = make_world(noise=30.0, regions=[])
    n = 10_000
    state = at(world, [(350, 200)] * n)
    nxt, tr = world.step(state, np.full(n, RIGHT), np.random.default_rng(5))
    # 450 + N(0, 30) >= 500 with probability ~ 0.048: those bump and stay.
    bumped = tr.bump == 1
    assert 0.03 < bumped.mean() < 0.07
    assert (nxt.x[bumped] == 350).all() and (nxt.y[bumped] == 200).all()
    assert (nxt.x[~bumped] < 500).all()


def _trajectory(seed: int, steps: int = 200) -> np.ndarray:
    world = make_world(slip=0.2, noise=5.0)
    rng = np.random.default_rng(seed)
    state = world.reset(rng, 3)
    out = []
    for _ in range(steps):
        actions = rng.integers(0, 4, size=3)
        state, tr = world.step(state, actions, rng)
        out.append(world.sensors(state, tr))
        done = tr.terminated | tr.truncated
        if done.any():
            fresh = world.reset(rng, 3)
            state = type(state)(
                *(np.where(done if a.ndim == 1 else done[:, None], f, a) for a, f in zip(state, fresh, strict=True))
            )
    return np.array(out)


def test_same_seed_same_trajectory():
    a, b, c = _trajectory(11), _trajectory(11), _trajectory(12)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)


def test_step_does_not_change_its_argument():
    world = make_world(slip=0.2, noise=5.0)
    state = at(world, [(200, 100), (0, 0)])
    copies = [a.copy() for a in state]
    world.step(state, np.array([UP, LEFT]), np.random.default_rng(0))
    for before, after in zip(copies, state, strict=True):
        np.testing.assert_array_equal(before, after)


def test_sensor_names_in_their_fixed_order():
    world = make_world()
    assert world.sensor_names == [
        "x",
        "y",
        "bump",
        "steps",
        "reward",
        "in:wall",
        "in:goal",
        "in:pit",
        "in:lamp",
        "in:crit",
        "color:lamp",
        "terminal",
    ]


def test_sensor_values_after_transitions():
    world = make_world()
    # 0: into the lamp while purple; 1: a bump at the origin (inside crit); 2: into the pit while purple.
    state = at(world, [(200, 200), (0, 0), (400, 100)], steps=4, color=1)
    nxt, tr = world.step(state, np.array([RIGHT, LEFT, UP]), np.random.default_rng(0))
    s = dict(zip(world.sensor_names, world.sensors(nxt, tr).T, strict=True))
    assert s["x"].tolist() == [300, 0, 400]
    assert s["y"].tolist() == [200, 0, 200]
    assert s["bump"].tolist() == [0, 1, 0]
    assert s["steps"].tolist() == [5, 5, 5]
    assert s["reward"].tolist() == pytest.approx([-0.01, -0.01, -0.01 - 3.0])
    assert s["in:wall"].tolist() == [0, 0, 0]
    assert s["in:goal"].tolist() == [0, 0, 0]
    assert s["in:pit"].tolist() == [0, 0, 1]
    assert s["in:lamp"].tolist() == [1, 0, 0]
    assert s["in:crit"].tolist() == [0, 1, 0]
    assert s["color:lamp"].tolist() == [-1, 0, 0]  # the colour's value inside the indicator, else 0
    assert s["terminal"].tolist() == [0, 0, 1]
    yellow = state._replace(colors=np.zeros_like(state.colors))
    nxt, tr = world.step(yellow, np.array([RIGHT, LEFT, UP]), np.random.default_rng(0))
    assert world.sensors(nxt, tr)[:, world.sensor_index["color:lamp"]].tolist() == [1, 0, 0]


def test_start_sensors_have_no_transition():
    world = make_world(start=[0, 0, 200, 200])
    state = world.reset(np.random.default_rng(0), 50)
    s = world.start_sensors(state)
    assert s.shape == (50, len(world.sensor_names))
    for name in ("bump", "reward", "steps", "terminal"):
        assert (s[:, world.sensor_index[name]] == 0).all()
    assert (s[:, world.sensor_index["in:crit"]] == 1).all()


def test_start_rectangle_is_drawn_uniformly_outside_obstacles_and_terminals():
    world = make_world(start=[0, 0, 500, 500])
    state = world.reset(np.random.default_rng(1), 20_000)
    assert not world.blocked(state.x, state.y).any()
    assert not (world.inside(state.x, state.y) & world.is_terminal).any()
    # 22 of 25 cells are allowed (wall, goal and pit excluded): each gets ~1/22 of the starts.
    cells = (state.x // 100).astype(int) * 5 + (state.y // 100).astype(int)
    counts = np.bincount(cells, minlength=25)
    allowed = counts > 0
    assert allowed.sum() == 22
    assert np.allclose(counts[allowed] / 20_000, 1 / 22, atol=0.006)
    assert len(np.unique(state.x)) > 19_000  # continuous, not on a lattice


def test_both_engines_refuse_an_impossible_start_the_same_way() -> None:
    """A spec that skipped validation (model_copy does not validate) must not start an agent inside a wall."""
    spec = RunSpec.model_validate({"world": {"start": [0, 0, 100, 100], "regions": REGIONS}, "demons": [{"name": "a"}]})
    covered = spec.world.model_copy(update={"start": [100.0, 200.0, 200.0, 300.0]})  # the wall exactly
    with pytest.raises(ImpossibleStartError) as numpy_error:
        World(covered).reset(np.random.default_rng(0), batch=3)
    with pytest.raises(ImpossibleStartError) as compiled_error:
        Simulation(spec.model_copy(update={"world": covered}), np.random.default_rng(0))
    assert str(numpy_error.value) == str(compiled_error.value) == IMPOSSIBLE_START
