"""The live view of Baird's star (`horde.worlds.baird`): its seven states, the agent's, and a demon's values.

A pure scene builder (as `phase_plane.py`), drawn in place of the phase plane for a run on `horde/Baird-v0`:
the six upper states on an arc above the lower one, a line from each to the lower state (the solid action,
the one the target policy always takes), each state a disc coloured by the chosen demon's value there (a
shared colour scale from the lowest to the highest of the seven), labelled with that value, and the agent as
a red sphere on the state it is in. A diverged demon (frozen, its weights set to 0) reads 0 everywhere: the
title says it diverged.
"""

from __future__ import annotations

import math

import numpy as np

from horde.view.colors import colormap
from horde.view.nodes import Node
from horde.worlds.baird import UPPER

RADIUS = 4.0  # of the arc of upper states, in scene units
DISC = 0.55  # a state's radius
LOWER_AT = (0.0, -3.0)


def star_positions() -> np.ndarray:
    """[7, 2] scene (x, y) of the states: 0..5 on an arc above, 6 below them."""
    angles = np.linspace(math.radians(150), math.radians(30), UPPER)  # [6] left to right
    upper = np.stack([RADIUS * np.cos(angles), RADIUS * np.sin(angles) - 0.5], axis=1)
    return np.vstack([upper, np.array([LOWER_AT])])


def star_nodes(demon: str, values: np.ndarray, state: int, diverged: bool = False) -> list[Node]:
    """The star with `demon`'s values [7] at its states and the agent at `state`."""
    where = star_positions()  # [7, 2]
    finite = np.where(np.isfinite(values), values, 0.0)  # [7]
    low, high = float(finite.min()), float(finite.max())
    colours = colormap(finite, low, high if high - low > 1e-12 else low + 1.0)  # [7, 3]
    lower = (*where[UPPER], 0.0)
    solid = np.array([[(*where[s], 0.0), lower] for s in range(UPPER)])  # [6, 2, 3]
    title = f"{demon}: diverged (frozen; its weights were set to 0)" if diverged else (
        f"{demon}: the value of each state, {low:.3g} to {high:.3g}")  # fmt: skip
    nodes = [
        Node("/star/solid", "lines", points=solid, color=(120, 120, 120), size=(2.0, 0.0, 0.0)),
        Node("/star/title", "label", position=(0.0, RADIUS + 1.2, 0.0), text=title, anchor="bottom-center"),
        Node("/star/legend", "label", position=(0.0, LOWER_AT[1] - 1.2, 0.0), anchor="top-center",
             text="grey lines: the solid action (to the lower state), the target policy's; dashed moves to any "
                  "upper state"),
    ]  # fmt: skip
    for s in range(UPPER + 1):
        x, y = where[s]
        colour = (int(colours[s][0]), int(colours[s][1]), int(colours[s][2]))
        nodes.append(Node(f"/star/state{s}", "sphere", position=(float(x), float(y), 0.0), size=(DISC, 0.0, 0.0),
                          color=colour))  # fmt: skip
        nodes.append(Node(f"/star/value{s}", "label", position=(float(x), float(y) - DISC - 0.15, 0.0),
                          text=f"s{s + 1}: {values[s]:.4g}", anchor="top-center"))  # fmt: skip
    x, y = where[min(max(state, 0), UPPER)]
    nodes.append(Node("/star/agent", "sphere", position=(float(x), float(y), DISC), size=(0.25, 0.0, 0.0),
                      color=(230, 60, 60)))  # fmt: skip
    return nodes
