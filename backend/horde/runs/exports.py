"""Exports people share: a run's history and a protocol's results as CSV or JSON, a run spec as TOML.

CSV files have one header row and one row per record, numbers written in full (`repr`), non-finite ones
empty; JSON files are lists of the same records with null for non-finite numbers. A run spec exported as
TOML reads back (`scenarios.parse_scenario`) as the same spec: a user can share exactly what ran.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Iterable, Sequence
from typing import Any, Literal

import tomli_w

from horde.core.experiment import ProtocolResult
from horde.runs.history import ALL_QUANTITIES, History
from horde.spec import RunSpec

Format = Literal["csv", "json"]
HISTORY_FIELDS = ("step", "demon", *ALL_QUANTITIES)
PROTOCOL_FIELDS = ("demon", "prediction", "truth", "truth_stderr", "error", "thesis", "positive", "negative", "none")


def finite_or_none(value: Any) -> Any:
    """The value, or None where it is a non-finite float (null in JSON, an empty cell in CSV)."""
    return None if isinstance(value, float) and not math.isfinite(value) else value


def history_records(history: History) -> list[dict[str, Any]]:
    """Every kept row of every demon: step, demon, prediction, cumulant, delta, rupee, ude, rmsve, rmspbe (by step,
    then demon; the last two empty on a world without discrete states)."""
    rows: list[dict[str, Any]] = []
    for name in history.names:
        series = history.series(name)
        for i, step in enumerate(series.steps.tolist()):
            row: dict[str, Any] = {"step": step, "demon": name}
            row.update({q: finite_or_none(float(series.values[q][i])) if q in series.values else None
                        for q in ALL_QUANTITIES})  # fmt: skip
            rows.append(row)
    order = {name: i for i, name in enumerate(history.names)}
    rows.sort(key=lambda r: (r["step"], order[r["demon"]]))
    return rows


def protocol_records(result: ProtocolResult) -> list[dict[str, Any]]:
    """One record per demon: prediction, truth ± stderr, error, the thesis's number, test-run counts."""
    out = []
    for d in result.demons:
        counts = d.counts.model_dump() if d.counts else {"positive": None, "negative": None, "none": None}
        out.append(
            {
                "demon": d.name,
                "prediction": finite_or_none(d.prediction),
                "truth": finite_or_none(d.truth),
                "truth_stderr": finite_or_none(d.truth_stderr),
                "error": finite_or_none(d.error),
                "thesis": finite_or_none(d.thesis),
                **counts,
            }
        )
    return out


def to_csv(records: Iterable[dict[str, Any]], fields: Sequence[str]) -> str:
    """One header row of `fields`, then a row per record: None an empty cell, floats written in full (repr)."""
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(fields)
    for record in records:
        writer.writerow(
            ["" if record.get(f) is None else (repr(v) if isinstance(v := record[f], float) else v) for f in fields]
        )
    return out.getvalue()


def spec_toml(spec: RunSpec) -> str:
    """The run spec as a scenario file (defaults written out, unset optional fields left out)."""
    data = spec.model_dump(mode="json", by_alias=True, exclude_none=True)
    header = f"# Horde Lab run spec{f' {spec.name!r}' if spec.name else ''}: `horde run` reads it as a scenario.\n"
    return header + tomli_w.dumps(data)
