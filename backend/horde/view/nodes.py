"""`Node`: one scene node described as plain data, so the scene can be built and tested without viser.

Positions and sizes are in scene units (see `scene.scene_scale`), z pointing up out of the floor.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Literal

import numpy as np

NodeKind = Literal["box", "sphere", "label", "lines", "image", "mesh", "arrows"]


@dataclass(frozen=True, eq=False)
class Node:
    """A scene node. Which fields matter depends on `kind`:

    - box: position (centre), size (x, y, z), color, opacity.
    - sphere: position (centre), size[0] (radius), color.
    - label: position, text, anchor (e.g. "bottom-left").
    - lines / arrows: points [N, 2, 3] (start and end of each segment or arrow), color,
      size[0] (line thickness in pixels, or arrow shaft radius in scene units).
    - image: position (centre), size (width, height, 0), image [H, W, 4] RGBA uint8, row 0 at the top.
    - mesh: points [V, 3] vertices, faces [F, 3], vertex_colors [V, 4] RGBA uint8.
    """

    name: str
    kind: NodeKind
    position: tuple[float, float, float] = (0.0, 0.0, 0.0)
    size: tuple[float, float, float] = (0.0, 0.0, 0.0)
    color: tuple[int, int, int] = (0, 0, 0)
    opacity: float | None = None
    text: str = ""
    anchor: str = "center-center"  # labels: which point of the text sits at `position`
    points: np.ndarray | None = None
    faces: np.ndarray | None = None
    vertex_colors: np.ndarray | None = None
    image: np.ndarray | None = None


def _same_value(a: object, b: object) -> bool:
    if a is b:
        return True
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return (isinstance(a, np.ndarray) and isinstance(b, np.ndarray) and a.shape == b.shape
                and np.array_equal(a, b))  # fmt: skip
    return a == b


FIELDS = tuple(f.name for f in fields(Node))


def changed_fields(a: Node, b: Node) -> frozenset[str]:
    """The fields in which two nodes differ (arrays compared by value, each field once)."""
    if a is b:
        return frozenset()
    return frozenset(name for name in FIELDS if not _same_value(getattr(a, name), getattr(b, name)))
