"""Expressions: cumulant, outcome and continuation of a question (DESIGN section 4). Data, never eval.

    Expr = number | {sensor = NAME} | {prediction = DEMON} | {add = [...]} | {mul = [...]} | {min = [...]}
         | {max = [...]} | {if = Expr, then = Expr, else = Expr}

The helpers read an expression's children, size, the demons and sensors it reads, and the range it can take.
"""

from __future__ import annotations

import math
from typing import Any

from pydantic import Field

from horde.spec.base import MAX_EXPR_DEPTH, MAX_EXPR_NODES, Finite, Model, Name


class SensorExpr(Model):
    sensor: str = Field(min_length=1, max_length=80, description="a sensor name, e.g. in:goal")


class PredictionExpr(Model):
    prediction: Name = Field(description="another demon's current prediction")


class AddExpr(Model):
    add: list[Expr] = Field(min_length=1, max_length=32)


class MulExpr(Model):
    mul: list[Expr] = Field(min_length=1, max_length=32)


class MinExpr(Model):
    min: list[Expr] = Field(min_length=1, max_length=32)


class MaxExpr(Model):
    max: list[Expr] = Field(min_length=1, max_length=32)


class IfExpr(Model):
    if_: Expr = Field(alias="if", description="counts as true where it is not 0")
    then: Expr
    else_: Expr = Field(alias="else")


Expr = Finite | SensorExpr | PredictionExpr | AddExpr | MulExpr | MinExpr | MaxExpr | IfExpr
for _model in (AddExpr, MulExpr, MinExpr, MaxExpr, IfExpr):
    _model.model_rebuild()


def expr_children(expr: Expr) -> list[Expr]:
    """The direct sub-expressions of an expression."""
    if isinstance(expr, AddExpr):
        return list(expr.add)
    if isinstance(expr, MulExpr):
        return list(expr.mul)
    if isinstance(expr, MinExpr):
        return list(expr.min)
    if isinstance(expr, MaxExpr):
        return list(expr.max)
    if isinstance(expr, IfExpr):
        return [expr.if_, expr.then, expr.else_]
    return []


def raw_expr_problem(data: Any) -> str | None:
    """Why unvalidated expression data is too deep or too large, else None.

    Runs before pydantic validates the expression: a union validated on deeply nested input multiplies
    its errors level by level, so depth and size are checked first, iteratively, on the raw data.
    """
    stack: list[tuple[Any, int]] = [(data, 1)]
    nodes = 0
    while stack:
        value, depth = stack.pop()
        if isinstance(value, dict):
            nodes += 1
            if depth > MAX_EXPR_DEPTH:
                return f"nested more than {MAX_EXPR_DEPTH} expressions deep"
            for child in value.values():
                stack.extend((item, depth + 1) for item in (child if isinstance(child, list) else [child]))
        else:
            nodes += 1
        if nodes > MAX_EXPR_NODES:
            return f"has more than {MAX_EXPR_NODES} nodes"
    return None


def expr_size(expr: Expr) -> int:
    return 1 + sum(expr_size(child) for child in expr_children(expr))


def expr_predictions(expr: Expr) -> set[str]:
    """Names of the demons whose predictions an expression reads."""
    found = {expr.prediction} if isinstance(expr, PredictionExpr) else set()
    for child in expr_children(expr):
        found |= expr_predictions(child)
    return found


def expr_interval(expr: Expr, bounds: dict[str, tuple[float, float]]) -> tuple[float, float]:
    """The range an expression can take, given each sensor's range (predictions are unbounded)."""
    if isinstance(expr, float | int):
        return float(expr), float(expr)
    if isinstance(expr, SensorExpr):
        return bounds.get(expr.sensor, (-math.inf, math.inf))
    if isinstance(expr, PredictionExpr):
        return -math.inf, math.inf
    if isinstance(expr, IfExpr):
        (a, b), (c, d) = expr_interval(expr.then, bounds), expr_interval(expr.else_, bounds)
        return min(a, c), max(b, d)
    parts = [expr_interval(child, bounds) for child in expr_children(expr)]
    lo, hi = parts[0]
    for a, b in parts[1:]:
        if isinstance(expr, AddExpr):
            lo, hi = lo + a, hi + b
        elif isinstance(expr, MulExpr):
            products = [p for p in (lo * a, lo * b, hi * a, hi * b) if not math.isnan(p)]
            lo, hi = (min(products), max(products)) if products else (-math.inf, math.inf)
        elif isinstance(expr, MinExpr):
            lo, hi = min(lo, a), min(hi, b)
        else:
            lo, hi = max(lo, a), max(hi, b)
    return lo, hi


def expr_sensors(expr: Expr) -> set[str]:
    found = {expr.sensor} if isinstance(expr, SensorExpr) else set()
    for child in expr_children(expr):
        found |= expr_sensors(child)
    return found
