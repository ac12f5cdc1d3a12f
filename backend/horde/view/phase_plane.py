"""The live view of a non-grid world: a phase plane of two sensors, a demon's value map over it, the trail.

Pure scene builders (as `scene.py`): the plane spans PLANE_SIZE scene units on each side, x to the right,
y up; the value map is a texture under the trail of the agent's recent (x, y) readings, with the axes'
names and ranges as labels.
"""

from __future__ import annotations

import math

import numpy as np

from horde.view.camera import FOV, MARGIN, PANEL_SHIFT, CameraPose
from horde.view.nodes import Node
from horde.view.scene import value_texture
from horde.worlds.phase_plane import Axis

PLANE_SIZE = 10.0
TRAIL_Z = 0.02


def phase_camera() -> CameraPose:
    """Straight down on the plane (its labels included), x to the right, y up, clear of the GUI panel."""
    distance = 0.5 * (PLANE_SIZE + 2.0) * MARGIN / math.tan(FOV / 2)
    cx = PANEL_SHIFT * PLANE_SIZE
    return CameraPose((cx, 0.0, distance), (cx, 0.0, 0.0), (0.0, 1.0, 0.0))


def to_plane(x: Axis, y: Axis, xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
    """[N, 3] scene points of sensor readings (clipped to the axes' ranges)."""
    u = np.clip((np.asarray(xs, float) - x.low) / (x.high - x.low), 0.0, 1.0) - 0.5
    v = np.clip((np.asarray(ys, float) - y.low) / (y.high - y.low), 0.0, 1.0) - 0.5
    return np.stack([u * PLANE_SIZE, v * PLANE_SIZE, np.full(len(u), TRAIL_Z)], axis=-1)


def phase_plane_nodes(x: Axis, y: Axis, demon: str, values: np.ndarray, trail: np.ndarray) -> list[Node]:
    """The value map of `demon` over (x, y), the trail [N, 2] of (x, y) readings, the agent at its end, labels."""
    finite = values[np.isfinite(values)]
    low, high = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 1.0)
    if high - low < 1e-12:
        high = low + 1.0
    nodes = [
        Node("/phase/map", "image", size=(PLANE_SIZE, PLANE_SIZE, 0.0),
             image=value_texture(values, low, high)),  # row j at y's j-th cell, as the grid's value maps
        Node("/phase/x_label", "label", position=(0.0, -PLANE_SIZE / 2 - 0.4, 0.0),
             text=f"{x.sensor} [{x.low:g}, {x.high:g}]", anchor="top-center"),
        Node("/phase/y_label", "label", position=(-PLANE_SIZE / 2 - 0.4, 0.0, 0.0),
             text=f"{y.sensor} [{y.low:g}, {y.high:g}]", anchor="center-right"),
        Node("/phase/title", "label", position=(0.0, PLANE_SIZE / 2 + 0.4, 0.0),
             text=f"{demon}: {low:.3g} (dark) to {high:.3g} (bright)", anchor="bottom-center"),
    ]  # fmt: skip
    if len(trail):
        points = to_plane(x, y, trail[:, 0], trail[:, 1])  # [N, 3]
        if len(points) > 1:
            nodes.append(Node("/phase/trail", "lines", points=np.stack([points[:-1], points[1:]], axis=1),
                              color=(255, 255, 255), size=(2.0, 0.0, 0.0)))  # fmt: skip
        nodes.append(Node("/phase/agent", "sphere", position=tuple(points[-1]), size=(0.15, 0.0, 0.0),
                          color=(230, 60, 60)))  # fmt: skip
    return nodes
