"""Colours of the scene: region kinds, indicator colour names, and the value map's colour scale."""

from __future__ import annotations

import colorsys
import zlib

import numpy as np

RGB = tuple[int, int, int]

FLOOR = (236, 236, 232)
BOUNDS = (60, 60, 60)
# One colour per region kind, the same as the World editor's drawing (frontend/src/lib/world.ts, KIND_COLORS;
# tests/view/test_region_colours.py holds the two together): a zone must not read as an obstacle's grey.
OBSTACLE = (91, 100, 114)  # #5b6472
POSITIVE = (21, 128, 61)  # #15803d, a terminal whose reward is > 0
NEGATIVE = (220, 38, 38)  # #dc2626, a terminal whose reward is < 0
NEUTRAL = (109, 40, 217)  # #6d28d9, a terminal whose reward is 0 (or not known: an indicator not drawn yet)
ZONE = (249, 115, 22)  # #f97316, translucent (ZONE_OPACITY)
ZONE_OPACITY = 0.55
UNDRAWN = (156, 163, 175)  # #9ca3af, an indicator before its colour is drawn
AGENT = (255, 255, 255)
TRAIL = (20, 20, 20)
ARROW = (250, 250, 250)

# Viridis (perceptually uniform, readable in grey), sampled at 9 evenly spaced points.
_VIRIDIS = np.array(
    [
        [68, 1, 84],
        [71, 44, 122],
        [59, 81, 139],
        [44, 113, 142],
        [33, 144, 141],
        [39, 173, 129],
        [92, 200, 99],
        [170, 220, 50],
        [253, 231, 37],
    ],
    dtype=float,
)


def named(name: str) -> RGB:
    """The RGB of a colour name: any CSS colour name ("yellow", "purple", "#ffcc00"); an unknown
    name gets a stable colour of its own, derived from the name."""
    try:
        from PIL import ImageColor  # viser needs imageio, which needs Pillow

        rgb = ImageColor.getrgb(name)
        return int(rgb[0]), int(rgb[1]), int(rgb[2])
    except (ImportError, ValueError):
        hue = (zlib.crc32(name.encode()) % 360) / 360.0
        r, g, b = colorsys.hsv_to_rgb(hue, 0.7, 0.9)
        return round(r * 255), round(g * 255), round(b * 255)


def terminal(reward: float | None) -> RGB:
    """Green for a positive reward, red for a negative one, grey for 0 or unknown (None)."""
    if reward is None or reward == 0:
        return NEUTRAL
    return POSITIVE if reward > 0 else NEGATIVE


def value_range(values: np.ndarray) -> tuple[float, float]:
    """(low, high) of the finite values, widened to a unit interval around a constant map."""
    finite = values[np.isfinite(values)]
    if finite.size == 0:
        return 0.0, 1.0
    low, high = float(finite.min()), float(finite.max())
    if high - low < 1e-12:
        return low - 0.5, high + 0.5
    return low, high


def colormap(values: np.ndarray, low: float, high: float) -> np.ndarray:
    """Viridis colours of values scaled from [low, high]: [..., 3] uint8 (non-finite values grey)."""
    t = np.clip((values - low) / (high - low), 0.0, 1.0)  # [...]
    t = np.where(np.isfinite(t), t, 0.0)
    position = t * (len(_VIRIDIS) - 1)
    lower = np.minimum(position.astype(int), len(_VIRIDIS) - 2)
    frac = (position - lower)[..., None]
    rgb = _VIRIDIS[lower] * (1.0 - frac) + _VIRIDIS[lower + 1] * frac  # [..., 3]
    rgb = np.where(np.isfinite(values)[..., None], rgb, 128.0)
    return np.round(rgb).astype(np.uint8)
