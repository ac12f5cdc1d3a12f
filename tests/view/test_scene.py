"""The scene of a run, built without a browser: which nodes exist, where, in which colour."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from horde.core.world import DOWN, UP
from horde.scenarios import load_scenario
from horde.spec import Region, RunSpec
from horde.view import colors, scene
from horde.view.nodes import Node
from horde.view.source import ViewSnapshot

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
S = 10.0 / 500.0  # scene units per world unit in the thesis worlds (500 x 500)


@pytest.fixture(scope="module")
def experiment1() -> RunSpec:
    return load_scenario(SCENARIOS / "experiment1.toml")


@pytest.fixture(scope="module")
def experiment3() -> RunSpec:
    return load_scenario(SCENARIOS / "experiment3.toml")


def snapshot_of(
    spec: RunSpec,
    x: float = 0.0,
    y: float = 0.0,
    trail: tuple[tuple[float, float], ...] = ((0.0, 0.0),),
    predictions: dict[str, float] | None = None,
    indicator_colors: dict[str, str] | None = None,
) -> ViewSnapshot:
    return ViewSnapshot(
        run_id="r1",
        spec=spec,
        x=x,
        y=y,
        trail=trail,
        episode=0,
        episode_step=len(trail) - 1,
        total_steps=len(trail) - 1,
        episode_return=0.0,
        status="paused",
        hz=10.0,
        predictions=predictions or {},
        rupee={},
        indicator_colors=indicator_colors or {},
    )


def by_name(nodes: list[Node]) -> dict[str, Node]:
    named = {node.name: node for node in nodes}
    assert len(named) == len(nodes), "node names must be unique"
    return named


# ----------------------------------------------------------------------------------------------
# The world


def test_experiment1_world_has_floor_bounds_and_every_region_with_its_label(experiment1: RunSpec) -> None:
    nodes = by_name(scene.world_nodes(experiment1.world, {}))
    assert set(nodes) == {
        "/world/floor",
        "/world/bounds",
        "/regions/goal",
        "/regions/pit",
        "/regions/wall",
        "/region_labels/goal",
        "/region_labels/pit",
        "/region_labels/wall",
    }
    floor = nodes["/world/floor"]
    assert floor.kind == "box"
    assert floor.size[:2] == pytest.approx((10.0, 10.0))
    assert floor.position[:2] == pytest.approx((5.0, 5.0))
    assert floor.position[2] + floor.size[2] / 2 == pytest.approx(0.0)  # its top is the floor
    bounds = nodes["/world/bounds"].points
    assert bounds is not None and bounds.shape == (4, 2, 3)
    assert bounds[:, :, :2].min() == 0.0 and bounds[:, :, :2].max() == pytest.approx(10.0)


@pytest.mark.parametrize(
    ("name", "centre", "color"),
    [
        ("goal", (450, 450), colors.POSITIVE),  # [400, 400, 500, 500], reward +1
        ("pit", (450, 250), colors.NEGATIVE),  # [400, 200, 500, 300], reward -1
        ("wall", (150, 250), colors.OBSTACLE),  # [100, 200, 200, 300]
    ],
)
def test_experiment1_regions_are_boxes_where_their_rects_are_in_their_kinds_colour(
    experiment1: RunSpec, name: str, centre: tuple[float, float], color: tuple[int, int, int]
) -> None:
    nodes = by_name(scene.world_nodes(experiment1.world, {}))
    box = nodes[f"/regions/{name}"]
    assert box.kind == "box"
    assert box.position[:2] == pytest.approx((centre[0] * S, centre[1] * S))
    assert box.size[:2] == pytest.approx((100 * S, 100 * S))
    assert box.position[2] == pytest.approx(box.size[2] / 2)  # standing on the floor
    assert box.color == color
    assert box.opacity is None
    label = nodes[f"/region_labels/{name}"]
    assert label.kind == "label" and label.text == name
    assert (label.position[:2], label.anchor) == (pytest.approx(box.position[:2]), "center-center")
    assert label.position[2] > box.size[2]  # above the box


def test_obstacles_stand_taller_than_terminals(experiment1: RunSpec) -> None:
    nodes = by_name(scene.world_nodes(experiment1.world, {}))
    assert nodes["/regions/wall"].size[2] > nodes["/regions/goal"].size[2]


@pytest.mark.parametrize(
    ("lamp", "north_west", "south_east"),
    [("yellow", colors.NEGATIVE, colors.POSITIVE), ("purple", colors.POSITIVE, colors.NEGATIVE)],
)
def test_experiment3_terminals_take_the_colour_of_their_reward_under_the_indicator(
    experiment3: RunSpec, lamp: str, north_west: tuple[int, int, int], south_east: tuple[int, int, int]
) -> None:
    nodes = by_name(scene.world_nodes(experiment3.world, {"lamp": lamp}))
    assert nodes["/regions/north_west"].color == north_west
    assert nodes["/regions/south_east"].color == south_east
    assert nodes["/regions/lamp"].color == colors.named(lamp)
    assert nodes["/regions/lamp"].position[:2] == pytest.approx((350 * S, 250 * S))
    assert nodes["/regions/wall"].color == colors.OBSTACLE


def test_experiment3_before_a_colour_is_drawn_terminals_and_indicator_are_neutral(
    experiment3: RunSpec,
) -> None:
    nodes = by_name(scene.world_nodes(experiment3.world, {}))
    for name in ("north_west", "south_east"):
        assert nodes[f"/regions/{name}"].color == colors.NEUTRAL
    assert nodes["/regions/lamp"].color == colors.UNDRAWN


def test_named_colours() -> None:
    assert colors.named("yellow") == (255, 255, 0)
    assert colors.named("purple") == (128, 0, 128)
    unknown = colors.named("no-such-colour")
    assert all(0 <= c <= 255 for c in unknown)
    assert unknown != colors.named("no-such-color"), "each unknown name gets a colour of its own"
    # Stable: the same in another process with another string-hash seed (the colour of a region must not change
    # from one server start to the next, as it would if derived from Python's salted hash()).
    code = "from horde.view import colors; print(*colors.named('no-such-colour'))"
    for seed in ("1", "2"):
        out = subprocess.run(
            [sys.executable, "-c", code],
            env={**os.environ, "PYTHONHASHSEED": seed},
            capture_output=True,
            text=True,
            timeout=60,
            check=True,
        ).stdout
        assert tuple(int(c) for c in out.split()) == unknown


def test_zones_are_translucent_orange(experiment1: RunSpec) -> None:
    zone = Region(name="critical", kind="zone", rect=[100, 300, 400, 500])
    world = experiment1.world.model_copy(update={"regions": [*experiment1.world.regions, zone]})
    node = by_name(scene.world_nodes(world, {}))["/regions/critical"]
    assert node.color == colors.ZONE
    assert node.opacity is not None and 0.0 < node.opacity < 1.0
    assert node.position[:2] == pytest.approx((250 * S, 400 * S))


# ----------------------------------------------------------------------------------------------
# The agent


def test_agent_trail_and_prediction_labels(experiment1: RunSpec) -> None:
    trail = ((0.0, 0.0), (100.0, 0.0), (100.0, 100.0))
    snap = snapshot_of(experiment1, 100.0, 100.0, trail, predictions={"base": 0.25, "steps_to_end": 31.04})
    nodes = by_name(scene.agent_nodes(snap, ["steps_to_end", "base", "missing"]))
    assert set(nodes) == {"/agent", "/trail", "/predictions"}
    agent = nodes["/agent"]
    radius = agent.size[0]
    assert agent.kind == "sphere" and agent.color == colors.AGENT
    # A lattice world: the state (100, 100) is the cell [100, 200) x [100, 200), drawn at its centre.
    assert agent.position == pytest.approx((3.0, 3.0, radius))
    segments = nodes["/trail"].points
    assert segments is not None and segments.shape == (2, 2, 3)
    assert segments[0, 0, :2] == pytest.approx((1.0, 1.0))  # the trail joins the cells' centres too
    assert segments[0, 1, :2] == pytest.approx((3.0, 1.0))
    assert segments[1, 1, :2] == pytest.approx((3.0, 3.0))
    label = nodes["/predictions"]
    assert label.text == "at the agent: steps_to_end 31  ·  base 0.25"  # in the order asked, unknown demons left out
    # Under the world, from its lower left corner down, wherever the agent is: it never covers a region's name
    # (every one inside the world; one at the lower edge stands up from it).
    assert label.position[:2] == pytest.approx((0.0, -scene.PREDICTIONS_GAP)) and label.anchor == "top-left"


def test_many_predictions_wrap_three_to_a_line_and_a_name_at_the_lower_edge_stands_inside(experiment1: RunSpec) -> None:
    names = [f"d{k}" for k in range(7)]
    snap = snapshot_of(experiment1, predictions={name: float(k) for k, name in enumerate(names)})
    label = by_name(scene.agent_nodes(snap, names))["/predictions"]
    assert label.text.split("\n") == ["at the agent: d0 0  ·  d1 1  ·  d2 2", "d3 3  ·  d4 4  ·  d5 5", "d6 6"]
    low = experiment1.world.model_copy(update={"regions": [r.model_copy(update={"rect": [0, 0, 100, 100]})
                                                           for r in experiment1.world.regions[:1]]})  # fmt: skip
    name = by_name(scene.world_nodes(low, {}))[f"/region_labels/{low.regions[0].name}"]
    assert name.anchor == "bottom-center" and name.position[1] == pytest.approx(scene.LABEL_INSET)


def test_no_trail_at_an_episode_start_and_no_label_without_demons(experiment1: RunSpec) -> None:
    nodes = by_name(scene.agent_nodes(snapshot_of(experiment1), []))
    assert set(nodes) == {"/agent"}


# ----------------------------------------------------------------------------------------------
# The value map


def rising_with_y(resolution: int) -> np.ndarray:
    """[res, res] values that grow with y only (row j at y_j)."""
    return np.repeat(np.arange(resolution, dtype=float)[:, None], resolution, axis=1)


def test_value_texture_puts_low_values_at_small_y_in_viridis(experiment1: RunSpec) -> None:
    nodes = by_name(scene.value_map_nodes(experiment1.world, "base", rising_with_y(8)))
    texture = nodes["/value_map/texture"]
    assert texture.kind == "image"
    assert texture.position[:2] == pytest.approx((5.0, 5.0)) and texture.size[:2] == pytest.approx((10.0, 10.0))
    image = texture.image
    assert image is not None and image.dtype == np.uint8 and image.shape[2] == 4
    assert image.shape[0] >= scene.TEXTURE_PIXELS and image.shape[0] % 8 == 0
    assert tuple(image[0, 0, :3]) == (68, 1, 84)  # row 0 (smallest y): the lowest value, dark purple
    assert tuple(image[-1, -1, :3]) == (253, 231, 37)  # the highest value, yellow
    assert nodes["/value_map/legend"].text == "base: 0 (purple) to 7 (yellow)"
    assert "/value_map/surface" not in nodes and "/value_map/arrows" not in nodes


def test_greedy_arrows_point_along_the_greedy_action_outside_obstacles_and_terminals(
    experiment1: RunSpec,
) -> None:
    res = scene.arrow_resolution(experiment1.world)
    assert res == 5  # one arrow per step of 100 in a 500-wide world
    greedy = np.full((res, res), UP)
    greedy[0, 0] = DOWN
    nodes = by_name(scene.value_map_nodes(experiment1.world, "base", rising_with_y(8), greedy))
    points = nodes["/value_map/arrows"].points
    assert points is not None
    assert points.shape == (25 - 3, 2, 3)  # goal, pit and wall cells have none
    starts, ends = points[:, 0], points[:, 1]
    centres = (starts + ends) / 2
    assert not any(np.allclose(c[:2], (1.5 * 2, 2.5 * 2)) for c in centres)  # the wall cell (150, 250)
    first = np.argmin(np.linalg.norm(centres[:, :2] - (1.0, 1.0), axis=1))  # the cell at (50, 50)
    assert centres[first, :2] == pytest.approx((1.0, 1.0))
    assert ends[first, 1] < starts[first, 1]  # down
    others = np.delete(np.arange(len(points)), first)
    assert np.all(ends[others, 1] > starts[others, 1])  # up
    assert np.allclose(ends[:, 0], starts[:, 0])


def test_the_surface_rises_with_the_prediction_in_the_3d_view(experiment1: RunSpec) -> None:
    values = rising_with_y(6)
    nodes = by_name(scene.value_map_nodes(experiment1.world, "base", values, three_d=True))
    surface = nodes["/value_map/surface"]
    assert surface.kind == "mesh" and surface.points is not None and surface.faces is not None
    heights = surface.points[:, 2].reshape(6, 6)
    assert heights.min() == pytest.approx(scene.SURFACE_BASE)
    assert heights.max() == pytest.approx(scene.SURFACE_BASE + scene.SURFACE_HEIGHT)
    assert np.all(np.diff(heights, axis=0) > 0) and np.allclose(np.diff(heights, axis=1), 0)
    assert surface.faces.shape == (2 * 2 * 5 * 5, 3) and surface.faces.max() == 35
    assert surface.vertex_colors is not None and surface.vertex_colors.shape == (36, 4)


def test_a_constant_value_map_lies_flat(experiment1: RunSpec) -> None:
    nodes = by_name(scene.value_map_nodes(experiment1.world, "base", np.full((4, 4), 3.0), three_d=True))
    surface = nodes["/value_map/surface"].points
    assert surface is not None and np.allclose(surface[:, 2], scene.SURFACE_BASE)


def test_build_scene_joins_the_three_parts(experiment3: RunSpec) -> None:
    snap = snapshot_of(experiment3, 200.0, 200.0, predictions={"colour": 0.0}, indicator_colors={"lamp": "yellow"})
    nodes = by_name(scene.build_scene(snap, ["colour"], "colour", np.zeros((4, 4))))
    assert {"/world/floor", "/regions/lamp", "/agent", "/predictions", "/value_map/texture"} <= set(nodes)
    assert nodes["/agent"].position[:2] == pytest.approx((5.0, 5.0))  # the centre of the start cell (200, 200)


def test_the_agent_is_drawn_in_its_cell_on_lattice_worlds_and_exactly_elsewhere(experiment1: RunSpec) -> None:
    assert scene.is_lattice(experiment1.world)
    assert scene.agent_point(experiment1.world, 0.0, 100.0) == (50.0, 150.0)
    noisy = experiment1.world.model_copy(update={"noise": 5.0})
    off_grid = experiment1.world.model_copy(update={"start": [10.0, 0.0]})
    for world in (noisy, off_grid):
        assert not scene.is_lattice(world)
        assert scene.agent_point(world, 12.5, 7.0) == (12.5, 7.0)
