"""The scene of one run as pure functions: a `ViewSnapshot` (and a value map) -> a list of `Node`s.

Scene units: the world's longer side is `SCENE_SIZE` long, the world's (0, 0) is the scene's origin,
world x and y are scene x and y, and z points up out of the floor. The builders do no I/O, so the
tests check names, positions and colours without a browser; `LiveView` applies the nodes with viser.

Node names: /world/floor, /world/bounds, /regions/<name>, /region_labels/<name>, /agent, /trail,
/predictions, /value_map/texture, /value_map/legend, /value_map/arrows, /value_map/surface.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from horde.core.world import DIRECTIONS
from horde.runs.readout import cell_centres
from horde.spec import IndicatorReward, Region, WorldSpec
from horde.view import colors
from horde.view.nodes import Node
from horde.view.source import ViewSnapshot

SCENE_SIZE = 10.0  # scene units along the world's longer side
FLOOR_THICKNESS = 0.05
REGION_HEIGHT = {"obstacle": 0.3, "terminal": 0.1, "zone": 0.04, "indicator": 0.12}
TEXTURE_Z = 0.01  # the value map lies just above the floor, under the regions
ARROW_Z = 0.08  # greedy actions float above zones, under terminals and obstacles
TRAIL_Z = 0.06
TRAIL_WIDTH = 3.0  # pixels
TEXTURE_ALPHA = 235
TEXTURE_PIXELS = 256  # least pixels per side of the value map's image
SURFACE_BASE = 0.02
SURFACE_ALPHA = 200  # of 255: the regions show through
SURFACE_HEIGHT = 0.3 * SCENE_SIZE  # the surface rises this high from the lowest to the highest value
MAX_ARROWS_PER_SIDE = 16
LABEL_INSET = 0.1  # scene units between a region's name and the world's lower edge
PREDICTIONS_GAP = 0.3  # scene units between the world's lower edge and the predictions under it
PREDICTIONS_TITLE = "at the agent:"
PREDICTIONS_PER_LINE = 3  # demons on a line of the predictions' label


def scene_scale(world: WorldSpec) -> float:
    """Scene units per world unit."""
    return SCENE_SIZE / max(world.width, world.height)


def to_scene(world: WorldSpec, x: float, y: float, z: float = 0.0) -> tuple[float, float, float]:
    """A world point (x, y) at height z (scene units) in scene coordinates."""
    s = scene_scale(world)
    return float(x * s), float(y * s), float(z)


def _fmt(value: float) -> str:
    return f"{value:.3g}" if np.isfinite(value) else str(value)


# ----------------------------------------------------------------------------------------------
# The world: floor, bounds, regions


def terminal_reward(region: Region, indicator_colors: Mapping[str, str]) -> float | None:
    """A terminal's reward now: its number, or its value under the indicator's current colour
    (None when that colour is not known)."""
    if isinstance(region.reward, IndicatorReward):
        color = indicator_colors.get(region.reward.indicator)
        return region.reward.values.get(color) if color is not None else None
    return None if region.reward is None else float(region.reward)


def region_color(region: Region, indicator_colors: Mapping[str, str]) -> tuple[tuple[int, int, int], float | None]:
    """(RGB, opacity) of a region: obstacle grey, terminal green / red by the sign of its reward now,
    zone translucent orange, indicator in its current colour (grey before one is drawn)."""
    if region.kind == "obstacle":
        return colors.OBSTACLE, None
    if region.kind == "terminal":
        return colors.terminal(terminal_reward(region, indicator_colors)), None
    if region.kind == "zone":
        return colors.ZONE, colors.ZONE_OPACITY
    color = indicator_colors.get(region.name)
    return (colors.named(color) if color else colors.UNDRAWN), None


def world_nodes(world: WorldSpec, indicator_colors: Mapping[str, str]) -> list[Node]:
    """The floor, its outline, and every region as a box with its name above it."""
    w, h, _ = to_scene(world, world.width, world.height)
    corners = np.array([[0, 0], [w, 0], [w, h], [0, h]], dtype=float)  # [4, 2]
    outline = np.zeros((4, 2, 3))
    outline[:, 0, :2], outline[:, 1, :2] = corners, np.roll(corners, -1, axis=0)
    nodes = [
        Node("/world/floor", "box", (w / 2, h / 2, -FLOOR_THICKNESS / 2), (w, h, FLOOR_THICKNESS), colors.FLOOR),
        Node("/world/bounds", "lines", color=colors.BOUNDS, size=(2.0, 0.0, 0.0), points=outline),
    ]
    for region in world.regions:
        x0, y0, _ = to_scene(world, region.rect[0], region.rect[1])
        x1, y1, _ = to_scene(world, region.rect[2], region.rect[3])
        height = REGION_HEIGHT[region.kind]
        color, opacity = region_color(region, indicator_colors)
        centre = ((x0 + x1) / 2, (y0 + y1) / 2)
        nodes.append(
            Node(
                f"/regions/{region.name}",
                "box",
                (*centre, height / 2),
                (x1 - x0, y1 - y0, height),
                color,
                opacity,
            )
        )
        if y0 <= 1e-9:  # at the world's lower edge: the name stands inside, clear of the predictions below
            label_at, anchor = (centre[0], y0 + LABEL_INSET), "bottom-center"
        else:
            label_at, anchor = centre, "center-center"
        nodes.append(
            Node(f"/region_labels/{region.name}", "label", (*label_at, height + 0.05), text=region.name, anchor=anchor)
        )
    return nodes


# ----------------------------------------------------------------------------------------------
# The agent: sphere, trail, live predictions


def is_lattice(world: WorldSpec) -> bool:
    """A world whose agent only ever stands on the corners of step x step cells: no noise, a start point
    on the lattice, and a step that divides the world."""
    step = world.step

    def divides(value: float) -> bool:
        return abs(value / step - round(value / step)) < 1e-9

    return (
        world.noise == 0
        and len(world.start) == 2
        and all(divides(v) for v in (world.width, world.height, world.start[0], world.start[1]))
    )


def agent_point(world: WorldSpec, x: float, y: float) -> tuple[float, float]:
    """Where the agent at (x, y) is drawn, in world units. On a lattice world a position stands for the
    cell whose lower-left corner it is (the features and the value map treat it so), and the agent is
    drawn at that cell's centre rather than on the grid lines; elsewhere it is drawn where it is."""
    if is_lattice(world):
        return x + world.step / 2, y + world.step / 2
    return x, y


def agent_radius(world: WorldSpec) -> float:
    """A third of a step, kept between 0.08 and 0.4 scene units."""
    return float(np.clip(0.3 * world.step * scene_scale(world), 0.08, 0.4))


def agent_nodes(snapshot: ViewSnapshot, demons: Sequence[str]) -> list[Node]:
    """The agent, its trail this episode, and a label with the predictions of `demons` at the agent's position,
    under the world (from its lower left corner down, PREDICTIONS_PER_LINE to a line), so that it never covers
    a region's name wherever the agent goes, nor hides under the view's panel (on the right) when it opens."""
    world = snapshot.spec.grid
    r = agent_radius(world)
    x, y, _ = to_scene(world, *agent_point(world, snapshot.x, snapshot.y))
    nodes = [Node("/agent", "sphere", (x, y, r), (r, 0.0, 0.0), colors.AGENT)]
    if len(snapshot.trail) >= 2:
        points = np.array(
            [to_scene(world, *agent_point(world, px, py), TRAIL_Z) for px, py in snapshot.trail]
        )  # [N, 3]
        segments = np.stack([points[:-1], points[1:]], axis=1)  # [N-1, 2, 3]
        nodes.append(Node("/trail", "lines", color=colors.TRAIL, size=(TRAIL_WIDTH, 0.0, 0.0), points=segments))
    entries = [f"{name} {_fmt(snapshot.predictions[name])}" for name in demons if name in snapshot.predictions]
    if entries:
        entries[0] = f"{PREDICTIONS_TITLE} {entries[0]}"
        rows = [entries[k : k + PREDICTIONS_PER_LINE] for k in range(0, len(entries), PREDICTIONS_PER_LINE)]
        text = "\n".join("  ·  ".join(row) for row in rows)
        nodes.append(Node("/predictions", "label", (0.0, -PREDICTIONS_GAP, 0.0), text=text, anchor="top-left"))
    return nodes


# ----------------------------------------------------------------------------------------------
# The value map: texture, legend, greedy arrows, 3-D surface


def arrow_resolution(world: WorldSpec) -> int:
    """Arrows per side: one per step of the world's longer side, between 2 and MAX_ARROWS_PER_SIDE."""
    return int(np.clip(round(max(world.width, world.height) / world.step), 2, MAX_ARROWS_PER_SIDE))


def value_texture(values: np.ndarray, low: float, high: float) -> np.ndarray:
    """[res, res] values (row j at y_j, see source.py) -> [n, n, 4] RGBA image with row 0 at y_0.

    viser lays images out in camera convention (+y down in the node's frame), so with the identity
    orientation an image's row 0 lies at the smallest y: the grid needs no flip. Each cell becomes a
    block of pixels (n >= TEXTURE_PIXELS) so that the browser's texture filtering keeps cells sharp.
    """
    repeat = max(1, -(-TEXTURE_PIXELS // values.shape[0]))  # ceil
    rgb = colors.colormap(values, low, high)  # [res, res, 3]
    rgb = np.repeat(np.repeat(rgb, repeat, axis=0), repeat, axis=1)  # [n, n, 3]
    alpha = np.full((*rgb.shape[:2], 1), TEXTURE_ALPHA, dtype=np.uint8)
    return np.concatenate([rgb, alpha], axis=-1)


def _cell_centres(world: WorldSpec, resolution: int, z: float) -> np.ndarray:
    """[res * res, 3] scene positions of the cell centres, row by row from the bottom."""
    w, h, _ = to_scene(world, world.width, world.height)
    gx, gy = np.meshgrid(*cell_centres(w, h, resolution))  # [res, res] each, row j holds y_j
    return np.stack([gx.ravel(), gy.ravel(), np.full(gx.size, z)], axis=-1)


def greedy_arrows(world: WorldSpec, greedy: np.ndarray) -> Node:
    """One arrow per cell in the direction of the greedy action, except in obstacles and terminals."""
    resolution = greedy.shape[0]
    s = scene_scale(world)
    centres = _cell_centres(world, resolution, ARROW_Z)  # [res * res, 3]
    cell = min(world.width, world.height) * s / resolution
    blocked = np.zeros(len(centres), dtype=bool)
    for region in world.regions:
        if region.kind in ("obstacle", "terminal"):
            x0, y0, x1, y1 = (v * s for v in region.rect)
            inside = (x0 <= centres[:, 0]) & (centres[:, 0] < x1) & (y0 <= centres[:, 1]) & (centres[:, 1] < y1)
            blocked |= inside
    direction = np.zeros((len(centres), 3))
    direction[:, :2] = DIRECTIONS[greedy.ravel()] * 0.3 * cell  # [res * res, 3]
    points = np.stack([centres - direction, centres + direction], axis=1)[~blocked]  # [N, 2, 3]
    size = (0.04 * cell, 0.12 * cell, 0.22 * cell)  # shaft radius, head radius, head length
    return Node("/value_map/arrows", "arrows", color=colors.ARROW, size=size, points=points)


def value_surface(world: WorldSpec, values: np.ndarray, low: float, high: float) -> Node:
    """A translucent height field over the cell centres, coloured like the texture, seen from both
    sides; its height spans SURFACE_HEIGHT from the lowest value to the highest."""
    resolution = values.shape[0]
    vertices = _cell_centres(world, resolution, SURFACE_BASE)  # [res * res, 3]
    finite = np.where(np.isfinite(values), values, low).ravel()  # [res * res]
    spread = float(finite.max() - finite.min())
    if spread > 1e-12:  # a constant map stays flat on the floor
        vertices[:, 2] += (finite - finite.min()) / spread * SURFACE_HEIGHT
    j, i = np.meshgrid(np.arange(resolution - 1), np.arange(resolution - 1), indexing="ij")
    v00 = (j * resolution + i).ravel()
    v10, v01, v11 = v00 + 1, v00 + resolution, v00 + resolution + 1
    up = np.concatenate([np.stack([v00, v10, v11], -1), np.stack([v00, v11, v01], -1)])  # [F, 3]
    faces = np.concatenate([up, up[:, ::-1]])  # both sides
    rgb = colors.colormap(values.ravel(), low, high)  # [res * res, 3]
    return Node(
        "/value_map/surface",
        "mesh",
        points=vertices,
        faces=faces.astype(np.int64),
        vertex_colors=np.concatenate([rgb, np.full((len(rgb), 1), SURFACE_ALPHA, dtype=np.uint8)], axis=-1),
    )


def value_map_nodes(
    world: WorldSpec, demon: str, values: np.ndarray, greedy: np.ndarray | None = None, three_d: bool = False
) -> list[Node]:
    """The value map of one demon: a texture on the floor with a legend, greedy arrows for a control
    demon, and (in the 3-D view) a surface whose height is the prediction.

    Args:
        world: the world drawn.
        demon: the demon's name (for the legend).
        values: [res, res] its predictions at the cell centres (source.py's grid convention).
        greedy: [res', res'] its greedy actions, or None.
        three_d: add the surface.
    """
    w, h, _ = to_scene(world, world.width, world.height)
    low, high = colors.value_range(values)
    legend = f"{demon}: {_fmt(low)} (purple) to {_fmt(high)} (yellow)"
    nodes = [
        Node(
            "/value_map/texture",
            "image",
            (w / 2, h / 2, TEXTURE_Z),
            (w, h, 0.0),
            image=value_texture(values, low, high),
        ),
        Node("/value_map/legend", "label", (0.0, h + 0.3, 0.0), text=legend, anchor="bottom-left"),
    ]
    if greedy is not None:
        nodes.append(greedy_arrows(world, greedy))
    if three_d:
        nodes.append(value_surface(world, values, low, high))
    return nodes


def build_scene(
    snapshot: ViewSnapshot,
    demons: Sequence[str] = (),
    value_demon: str | None = None,
    values: np.ndarray | None = None,
    greedy: np.ndarray | None = None,
    three_d: bool = False,
) -> list[Node]:
    """Every node of the scene of one run (LiveView refreshes the three parts at different rates)."""
    nodes = world_nodes(snapshot.spec.grid, snapshot.indicator_colors) + agent_nodes(snapshot, demons)
    if value_demon is not None and values is not None:
        nodes += value_map_nodes(snapshot.spec.grid, value_demon, values, greedy, three_d)
    return nodes
