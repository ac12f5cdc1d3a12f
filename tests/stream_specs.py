"""The tests' stream-world specs (a robot's sensors pushed from outside), written once."""

from __future__ import annotations

from typing import Any

LIGHT_WHEEL: list[dict[str, Any]] = [{"name": "light", "low": 0, "high": 1}, {"name": "wheel", "low": -1, "high": 1}]


def tiled(sensors: list[dict[str, Any]], tilings: int, tiles: int, size: int) -> dict[str, Any]:
    """Tile coding over each of `sensors` across its [low, high]."""
    columns = [{"sensor": s["name"], "low": s["low"], "high": s["high"]} for s in sensors]
    return {"kind": "sensors", "tilings": tilings, "tiles": tiles, "size": size, "sensors": columns}


def nexting(sensor: str, discount: float) -> dict[str, Any]:
    """A TD demon named `{sensor}_g{discount}` predicting the discounted sum of `sensor`."""
    return {"name": f"{sensor}_g{discount:g}", "learner": "td", "cumulant": {"sensor": sensor}, "discount": discount}


def robot(features: dict[str, Any], *demons: dict[str, Any], actions: int = 2) -> dict[str, Any]:
    """A run spec named "robot" whose world is a stream of LIGHT_WHEEL."""
    world = {"kind": "stream", "actions": actions, "sensors": LIGHT_WHEEL}
    return {"name": "robot", "world": world, "features": features, "demons": list(demons)}
