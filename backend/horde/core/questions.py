"""Compile question expressions (cumulant, outcome, continuation) into one array program.

All expressions of many demons compile once into a table of nodes (shared sub-expressions stored
once), sorted into levels by height. Evaluating the program is a fixed handful of numpy operations
per level (one gather for the sensors, one for the predictions, one `reduceat` per operator), for any
number of demons: no Python work per demon per step. The engine evaluates the same node table compiled
(`evaluate_nodes`, over `Program.table`), a stage at a time.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numba import njit

from horde.core.engine.layout import NO_NRT
from horde.spec import AddExpr, Expr, IfExpr, MaxExpr, MinExpr, MulExpr, PredictionExpr, SensorExpr, expr_children

NODE_KINDS = ("const", "sensor", "prediction", "add", "mul", "min", "max", "if")
N_CONST, N_SENSOR, N_PREDICTION, N_ADD, N_MUL, N_MIN, N_MAX, N_IF = range(8)
_OPERATORS: dict[type, str] = {AddExpr: "add", MulExpr: "mul", MinExpr: "min", MaxExpr: "max"}
_REDUCERS = {"add": np.add, "mul": np.multiply, "min": np.minimum, "max": np.maximum}


@dataclass(frozen=True)
class _Level:
    """The operator nodes of one height, grouped by operator."""

    reduce: dict[tuple[str, int], tuple[np.ndarray, list[np.ndarray]]] = field(default_factory=dict)
    # (op, arity) -> (output nodes [m], for each child position j the j-th children [m])
    branch: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None = None
    # (output nodes, condition nodes, then nodes, else nodes)


class Program:
    """A compiled list of expressions, evaluated on a batch of sensor vectors.

    Args:
        exprs: the expressions, one output column each.
        sensor_index: sensor name -> column of the sensor vector.
        demon_index: demon name -> column of the predictions vector.
    """

    def __init__(self, exprs: Sequence[Expr], sensor_index: dict[str, int], demon_index: dict[str, int]) -> None:
        self._keys: dict[tuple[object, ...], int] = {}
        self._kinds: list[str] = []
        self._args: list[object] = []
        self._heights: list[int] = []
        self._sensor_index = sensor_index
        self._demon_index = demon_index
        self.outputs = np.array([self._node(e) for e in exprs], dtype=np.int64)  # [E]
        self.num_nodes = len(self._kinds)
        kinds = np.array(self._kinds, dtype=object)
        self._const_nodes = np.nonzero(kinds == "const")[0]
        self._const_values = np.array([self._args[i] for i in self._const_nodes], dtype=float)
        self._sensor_nodes = np.nonzero(kinds == "sensor")[0]
        self._sensor_columns = np.array([self._args[i] for i in self._sensor_nodes], dtype=np.int64)
        self._prediction_nodes = np.nonzero(kinds == "prediction")[0]
        self._prediction_columns = np.array([self._args[i] for i in self._prediction_nodes], dtype=np.int64)
        self._levels = self._build_levels()
        self.reads_predictions = len(self._prediction_nodes) > 0

    def _node(self, expr: Expr) -> int:
        """Add an expression's node (and its children) once; return its index."""
        children: list[int] = []
        arg: object
        if isinstance(expr, bool | int | float):
            kind, arg = "const", float(expr)
        elif isinstance(expr, SensorExpr):
            kind, arg = "sensor", self._sensor_index[expr.sensor]
        elif isinstance(expr, PredictionExpr):
            kind, arg = "prediction", self._demon_index[expr.prediction]
        elif isinstance(expr, IfExpr):
            kind, arg = "if", None
            children = [self._node(expr.if_), self._node(expr.then), self._node(expr.else_)]
        else:
            kind = _OPERATORS[type(expr)]
            arg = None
            children = [self._node(child) for child in expr_children(expr)]
        key = (kind, arg, tuple(children))
        if key in self._keys:
            return self._keys[key]
        index = len(self._kinds)
        self._keys[key] = index
        self._kinds.append(kind)
        self._args.append(children if children else arg)
        self._heights.append(1 + max((self._heights[c] for c in children), default=-1))
        return index

    def _children(self, node: int) -> list[int]:
        arg = self._args[node]
        return arg if isinstance(arg, list) else []

    def _build_levels(self) -> list[_Level]:
        heights = np.array(self._heights, dtype=np.int64)
        levels = []
        for height in range(1, int(heights.max(initial=0)) + 1):
            level = _Level()
            nodes = [i for i in range(len(self._kinds)) if heights[i] == height]
            by_shape: dict[tuple[str, int], list[int]] = {}
            for i in nodes:
                if self._kinds[i] in _REDUCERS:
                    by_shape.setdefault((self._kinds[i], len(self._children(i))), []).append(i)
            for (op, arity), mine in by_shape.items():
                columns = [np.array([self._children(i)[j] for i in mine], dtype=np.int64) for j in range(arity)]
                level.reduce[(op, arity)] = (np.array(mine, dtype=np.int64), columns)
            branches = [i for i in nodes if self._kinds[i] == "if"]
            if branches:
                c, t, e = (np.array([self._args[i][j] for i in branches]) for j in range(3))  # type: ignore[index]
                level = _Level(level.reduce, (np.array(branches, dtype=np.int64), c, t, e))
            levels.append(level)
        return levels

    def table(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The node table for compiled kernels: (kind codes [N], argument [N], child starts [N + 1],
        children [C]). Children always come before their parent; kind codes index NODE_KINDS."""
        kinds = np.array([NODE_KINDS.index(k) for k in self._kinds], dtype=np.int64)
        argument = np.zeros(self.num_nodes)
        children: list[int] = []
        starts = [0]
        for i, (kind, arg) in enumerate(zip(self._kinds, self._args, strict=True)):
            if kind in ("const", "sensor", "prediction"):
                argument[i] = float(arg)  # type: ignore[arg-type]
            else:
                children.extend(arg)  # type: ignore[arg-type]
            starts.append(len(children))
        return kinds, argument, np.array(starts, dtype=np.int64), np.array(children, dtype=np.int64)

    def evaluate(self, sensors: np.ndarray, predictions: np.ndarray | None = None) -> np.ndarray:
        """Values of every expression.

        Args:
            sensors: [B, S] sensor vectors of the next state.
            predictions: [B, D] current predictions of all demons (needed if any expression reads one).

        Returns:
            [B, E] one column per compiled expression.
        """
        batch = sensors.shape[0]
        values = np.empty((batch, self.num_nodes))  # [B, N]
        values[:, self._const_nodes] = self._const_values
        values[:, self._sensor_nodes] = sensors[:, self._sensor_columns]
        if self.reads_predictions:
            if predictions is None:
                raise ValueError("these expressions read predictions; pass them")
            values[:, self._prediction_nodes] = predictions[:, self._prediction_columns]
        for level in self._levels:
            for (op, _), (nodes, columns) in level.reduce.items():
                # A left fold, child by child, so that sums add in the order written (as the reference does).
                acc = values[:, columns[0]]
                for column in columns[1:]:
                    acc = _REDUCERS[op](acc, values[:, column])
                values[:, nodes] = acc
            if level.branch is not None:
                nodes, cond, then, other = level.branch
                values[:, nodes] = np.where(values[:, cond] != 0.0, values[:, then], values[:, other])
        return values[:, self.outputs]


@njit(**NO_NRT)
def evaluate_nodes(progs, stage, sensors, pred, values):
    """Every node of a stage's program (`engine.layout.Programs`; children come before parents) into values,
    from the sensors of s_{t+1} and the predictions (per slot) as they stand."""
    kinds, args, starts, children = progs.node_kind, progs.node_arg, progs.node_start, progs.node_children
    for n in range(progs.stage_lo[stage], progs.stage_hi[stage]):
        kind = kinds[n]
        if kind == N_CONST:
            values[n] = args[n]
        elif kind == N_SENSOR:
            values[n] = sensors[int(args[n])]
        elif kind == N_PREDICTION:
            values[n] = pred[int(args[n])]
        elif kind == N_IF:
            c = children[starts[n]]
            values[n] = values[children[starts[n] + 1]] if values[c] != 0.0 else values[children[starts[n] + 2]]
        else:
            acc = values[children[starts[n]]]
            for j in range(starts[n] + 1, starts[n + 1]):
                x = values[children[j]]
                if kind == N_ADD:
                    acc = acc + x
                elif kind == N_MUL:
                    acc = acc * x
                elif kind == N_MIN:
                    acc = min(acc, x)
                else:
                    acc = max(acc, x)
            values[n] = acc
