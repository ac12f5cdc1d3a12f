"""A study's results as JSON-ready objects and as CSV text (for `--json`, REST exports and the dashboard).

Per configuration: its axis values (`axes`), `runs`, whether it is the `best`, the relative error over all
demons (`error`, `ci_low`, `ci_high`: final; `auc`, `auc_low`, `auc_high`: mean over the learning curve),
the learning curve, and per demon its final `error`, `ci_low`, `ci_high` (in the question's own units),
`auc` and its curve. Non-finite numbers become null.
"""

from __future__ import annotations

import csv
import io
import math
from typing import Any

from horde.studies.stats import Band, ConfigSummary


def _num(value: float) -> float | None:
    return value if math.isfinite(value) else None


def _curve(band: Band) -> dict[str, list[float | None]]:
    return {
        "mean": [_num(v) for v in band.mean],
        "low": [_num(v) for v in band.low],
        "high": [_num(v) for v in band.high],
    }


def summary_json(summary: ConfigSummary) -> dict[str, Any]:
    """One configuration as a JSON-ready object."""
    return {
        "index": summary.index,
        "axes": summary.axes,
        "runs": summary.runs,
        "best": summary.best,
        "truth": summary.truth,
        "episodes": summary.episodes,
        "error": _num(summary.final.mean[0]),
        "ci_low": _num(summary.final.low[0]),
        "ci_high": _num(summary.final.high[0]),
        "auc": _num(summary.auc.mean[0]),
        "auc_low": _num(summary.auc.low[0]),
        "auc_high": _num(summary.auc.high[0]),
        "curve": _curve(summary.curve),
        "returns": _curve(summary.returns),
        "positive": _curve(positive) if isinstance(positive := summary.extra.get("positive"), Band) else None,
        "demons": {
            name: {
                "error": _num(d.final.mean[0]),
                "ci_low": _num(d.final.low[0]),
                "ci_high": _num(d.final.high[0]),
                "auc": _num(d.auc.mean[0]),
                "curve": _curve(d.curve),
                "rupee": _curve(d.rupee),
            }
            for name, d in summary.demons.items()
        },
    }


def results_json(summaries: list[ConfigSummary]) -> list[dict[str, Any]]:
    return [summary_json(s) for s in summaries]


CSV_FIELDS = ("demon", "error", "ci_low", "ci_high", "auc", "auc_low", "auc_high")


def results_csv(summaries: list[ConfigSummary]) -> str:
    """One row per configuration and demon (and a row `demon = *` for the relative error over all demons)."""
    paths = list(summaries[0].axes) if summaries else []
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(["config", *paths, "runs", "best", *CSV_FIELDS])
    for s in summaries:
        head = [s.index, *(s.axes[p] for p in paths), s.runs, int(s.best)]
        rows = [("*", s.final, s.auc)] + [(n, d.final, d.auc) for n, d in s.demons.items()]
        for name, final, auc in rows:
            numbers = (final.mean[0], final.low[0], final.high[0], auc.mean[0], auc.low[0], auc.high[0])
            writer.writerow([*head, name, *("" if not math.isfinite(v) else repr(v) for v in numbers)])
    return out.getvalue()
