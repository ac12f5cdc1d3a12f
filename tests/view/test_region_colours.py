"""The live view and the World editor draw each region kind in one colour: a zone drawn orange in the editor
is orange in the view, not grey beside the obstacles' grey. The editor's palette is TypeScript
(frontend/src/lib/world.ts, KIND_COLORS and ZONE_OPACITY); this reads it and compares it with colors.py."""

from __future__ import annotations

import re
from pathlib import Path

from horde.view import colors

WORLD_TS = Path(__file__).resolve().parents[2] / "frontend" / "src" / "lib" / "world.ts"


def editor_palette() -> dict[str, str]:
    """KIND_COLORS of world.ts: kind -> "#rrggbb"."""
    block = re.search(r"export const KIND_COLORS = \{(.*?)\} as const;", WORLD_TS.read_text(), re.S)
    assert block, "KIND_COLORS not found in world.ts"
    return dict(re.findall(r'(\w+): "(#[0-9a-fA-F]{6})"', block.group(1)))


def hex_of(rgb: tuple[int, int, int]) -> str:
    return "#" + "".join(f"{c:02x}" for c in rgb)


def test_every_region_kind_has_the_editors_colour_in_the_view() -> None:
    view = {
        "obstacle": colors.OBSTACLE,
        "positive": colors.POSITIVE,
        "negative": colors.NEGATIVE,
        "neutral": colors.NEUTRAL,
        "zone": colors.ZONE,
        "undrawn": colors.UNDRAWN,
    }
    assert editor_palette() == {kind: hex_of(rgb) for kind, rgb in view.items()}


def test_a_zone_is_as_translucent_in_both() -> None:
    found = re.search(r"export const ZONE_OPACITY = ([0-9.]+);", WORLD_TS.read_text())
    assert found and float(found.group(1)) == colors.ZONE_OPACITY


def test_a_zone_is_told_from_an_obstacle() -> None:
    """The two kinds a user confused: far apart in colour (not two greys)."""
    distance = sum((a - b) ** 2 for a, b in zip(colors.ZONE, colors.OBSTACLE, strict=True)) ** 0.5
    assert distance > 150, distance
