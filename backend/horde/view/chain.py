"""The live view of a chain world (`horde.worlds.chains`): every state's value beside the truth, the book's
figure 9.1 drawn as the run learns.

A pure scene builder (as `star.py`), drawn in place of the phase plane for a run on a chain: the states in a
row along x (the book's order, left to right), the chosen demon's value at each state as a blue line above
them (y up is the value), the true values as a black line, the TD fixed point of the demon's features as a
dashed-looking grey one where it differs from the truth, a zero line, the agent as a red sphere on its state,
and a title with the errors (RMSVE and RMSPBE, on-policy weighting). A diverged demon reads 0: the title says
so.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from horde.view.nodes import Node


@dataclass(frozen=True)
class ChainPicture:
    """What the drawing needs of a run on a chain (`ManagerSource.chain`)."""

    demon: str
    states: np.ndarray  # [N]
    values: np.ndarray  # [N]
    exact: np.ndarray | None  # [N]
    fixed_point: np.ndarray | None  # [N]
    agent: int
    errors: str  # ", RMSVE 0.1, RMSPBE 0.01" (on-policy weighting), or ""
    diverged: bool

    @classmethod
    def of(cls, demon: str, report: dict[str, object], agent: int, diverged: bool) -> ChainPicture:
        """From `horde.worlds.state_values.values_report`'s row of the demon."""
        exact, fixed = report.get("exact"), report.get("fixed_point")
        errors = ""
        if "rmsve" in report:
            errors = f"; RMSVE {float(report['rmsve']):.3g}, RMSPBE {float(report['rmspbe']):.3g}"  # type: ignore[arg-type]
        return cls(demon, np.asarray(report["states"]), np.asarray(report["values"], dtype=float),
                   None if exact is None else np.asarray(exact, dtype=float),
                   None if fixed is None else np.asarray(fixed, dtype=float), agent, errors, diverged)  # fmt: skip

    def nodes(self) -> list[Node]:
        return chain_nodes(self.demon, self.states, self.values, self.exact, self.fixed_point, self.agent,
                           self.errors, self.diverged)  # fmt: skip


WIDTH = 12.0  # the row of states, in scene units
HEIGHT = 6.0  # the value range drawn, in scene units


def _polyline(xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
    """[N - 1, 2, 3] the segments joining consecutive points (z 0)."""
    points = np.stack([xs, ys, np.zeros_like(xs)], axis=1)  # [N, 3]
    return np.stack([points[:-1], points[1:]], axis=1)


def chain_nodes(demon: str, states: np.ndarray, values: np.ndarray, exact: np.ndarray | None,
                fixed_point: np.ndarray | None, agent: int, errors: str = "",
                diverged: bool = False) -> list[Node]:  # fmt: skip
    """The chain with `demon`'s values [N] and the truths [N] at its states [N], the agent at state `agent`."""
    n = len(states)
    finite = np.where(np.isfinite(values), values, 0.0)
    shown = [finite] + [a for a in (exact, fixed_point) if a is not None]
    low = min(0.0, *(float(a.min()) for a in shown))
    high = max(0.0, *(float(a.max()) for a in shown))
    span = high - low if high - low > 1e-12 else 1.0
    xs = np.linspace(-WIDTH / 2, WIDTH / 2, n) if n > 1 else np.zeros(1)
    y_of = lambda v: (np.asarray(v, dtype=float) - low) / span * HEIGHT - HEIGHT / 2  # noqa: E731
    title = f"{demon}: diverged (frozen; its weights were set to 0)" if diverged else (
        f"{demon}: the value of each state (blue) and the truth (black){errors}")  # fmt: skip
    nodes = [
        Node("/chain/zero", "lines", points=_polyline(xs[[0, -1]], y_of([0.0, 0.0])), color=(200, 200, 200),
             size=(1.0, 0.0, 0.0)),
        Node("/chain/title", "label", position=(0.0, HEIGHT / 2 + 1.0, 0.0), text=title, anchor="bottom-center"),
        Node("/chain/low", "label", position=(-WIDTH / 2 - 0.3, float(y_of(low)), 0.0), text=f"{low:.3g}",
             anchor="center-right"),
        Node("/chain/high", "label", position=(-WIDTH / 2 - 0.3, float(y_of(high)), 0.0), text=f"{high:.3g}",
             anchor="center-right"),
        Node("/chain/first", "label", position=(float(xs[0]), -HEIGHT / 2 - 0.4, 0.0), text=f"state {states[0]}",
             anchor="top-center"),
        Node("/chain/last", "label", position=(float(xs[-1]), -HEIGHT / 2 - 0.4, 0.0), text=f"state {states[-1]}",
             anchor="top-center"),
    ]  # fmt: skip
    if fixed_point is not None and exact is not None and np.abs(fixed_point - exact).max() > 1e-3 * span:
        nodes.append(Node("/chain/fixed", "lines", points=_polyline(xs, y_of(fixed_point)), color=(150, 150, 150),
                          size=(2.0, 0.0, 0.0)))  # fmt: skip
    if exact is not None:
        nodes.append(Node("/chain/truth", "lines", points=_polyline(xs, y_of(exact)), color=(20, 20, 20),
                          size=(2.0, 0.0, 0.0)))  # fmt: skip
    nodes.append(Node("/chain/values", "lines", points=_polyline(xs, y_of(finite)), color=(0, 114, 178),
                      size=(3.0, 0.0, 0.0)))  # fmt: skip
    if n <= 25:  # a disc and its number at every state of a short chain
        for i in range(n):
            nodes.append(Node(f"/chain/state{i}", "sphere", position=(float(xs[i]), float(y_of(finite[i])), 0.0),
                              size=(0.12, 0.0, 0.0), color=(0, 114, 178)))  # fmt: skip
    where = np.flatnonzero(states == agent)
    if where.size:
        i = int(where[0])
        nodes.append(Node("/chain/agent", "sphere", position=(float(xs[i]), float(y_of(finite[i])), 0.3),
                          size=(0.25, 0.0, 0.0), color=(230, 60, 60)))  # fmt: skip
    return nodes
