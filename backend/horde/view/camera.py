"""Camera poses of the view: straight down on the world (the default, 2-D) and tilted (3-D)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from horde.spec import WorldSpec
from horde.view.scene import to_scene

FOV = math.radians(30.0)  # vertical field of view: narrow, so that the top-down view looks flat
MARGIN = 1.4  # the world's longer side fills 1 / MARGIN of the view's height
PANEL_SHIFT = 0.18  # of the world's width: the camera looks right of centre, clear of the GUI panel


@dataclass(frozen=True)
class CameraPose:
    """Where a camera is, what it looks at, which way is up on screen (scene coordinates)."""

    position: tuple[float, float, float]
    look_at: tuple[float, float, float]
    up: tuple[float, float, float]
    fov: float = FOV


def _centre_and_distance(world: WorldSpec) -> tuple[float, float, float]:
    w, h, _ = to_scene(world, world.width, world.height)
    distance = 0.5 * max(w, h) * MARGIN / math.tan(FOV / 2)
    return w / 2 + PANEL_SHIFT * w, h / 2, distance


def top_down(world: WorldSpec) -> CameraPose:
    """Looking straight down (-z) with world +y up on screen and +x to the right."""
    cx, cy, distance = _centre_and_distance(world)
    return CameraPose((cx, cy, distance), (cx, cy, 0.0), (0.0, 1.0, 0.0))


def tilted(world: WorldSpec) -> CameraPose:
    """From the south, 50 degrees above the floor, z up: the value surface shows its relief."""
    cx, cy, distance = _centre_and_distance(world)
    elevation = math.radians(50.0)
    position = (cx, cy - distance * math.cos(elevation), distance * math.sin(elevation))
    return CameraPose(position, (cx, cy, 0.0), (0.0, 0.0, 1.0))
