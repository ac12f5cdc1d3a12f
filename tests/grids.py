"""The tests' grid worlds, written once: the thesis-like 500 x 500 lattice and its regions.

`grid(GOAL, PIT, WALL, slip=0.1)` is a WorldSpec body (a dict, so that a test can still send it over REST
or break it); the regions are plain dicts too, and `lamp` / `lamp_terminal` write an indicator and a
terminal whose reward depends on the indicator's colour without the nested lists.
"""

from __future__ import annotations

from typing import Any

GOAL: dict[str, Any] = {"name": "goal", "kind": "terminal", "rect": [400, 400, 500, 500], "reward": 1}
PIT: dict[str, Any] = {"name": "pit", "kind": "terminal", "rect": [400, 200, 500, 300], "reward": -1}
WALL: dict[str, Any] = {"name": "wall", "kind": "obstacle", "rect": [100, 200, 200, 300]}
CRIT: dict[str, Any] = {"name": "crit", "kind": "zone", "rect": [100, 300, 400, 500]}


def grid(*regions: dict[str, Any], **fields: Any) -> dict[str, Any]:
    """A 500 x 500 world of 100-unit steps starting at (0, 0), episodes of at most 100 steps, `regions`."""
    world = {"width": 500, "height": 500, "step": 100, "start": [0, 0], "max_steps": 100, "regions": list(regions)}
    return world | fields


def lamp(rect: list[float], name: str = "lamp", **colors: tuple[float, float]) -> dict[str, Any]:
    """An indicator region; each colour is `name=(value, probability)`."""
    return {
        "name": name,
        "kind": "indicator",
        "rect": rect,
        "colors": [{"name": c, "value": v, "probability": p} for c, (v, p) in colors.items()],
    }


def lamp_terminal(name: str, rect: list[float], indicator: str = "lamp", **rewards: float) -> dict[str, Any]:
    """A terminal whose reward is `rewards[colour]` of `indicator`'s colour this episode."""
    return {"name": name, "kind": "terminal", "rect": rect, "reward": {"indicator": indicator, "values": rewards}}
