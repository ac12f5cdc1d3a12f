"""A study's results as JSON-ready objects and as CSV text (for `--json`, REST exports and the dashboard).

Per configuration: its axis values (`axes`), `runs`, whether it is the `best`, whether it `diverged` (a run's
error non-finite or beyond `stats.DIVERGED_ERROR`, or a demon frozen by the engine), the relative error over all
demons (`error`, `ci_low`, `ci_high`: final; `auc`, `auc_low`, `auc_high`: mean over the learning curve),
the learning curve, and per demon its final `error`, `ci_low`, `ci_high` (in the question's own units),
`auc` and its curve. Non-finite numbers become null.

Two CSV files: `results_csv`, a row per configuration and demon (final error and AUC with their intervals),
and `curves_csv`, the learning curves in long format: a row per configuration, demon and checkpoint.
"""

from __future__ import annotations

from typing import Any

from horde.runs.exports import finite_or_none, to_csv
from horde.studies.stats import Band, ConfigSummary


def _curve(band: Band) -> dict[str, list[float | None]]:
    return {
        "mean": [finite_or_none(v) for v in band.mean],
        "low": [finite_or_none(v) for v in band.low],
        "high": [finite_or_none(v) for v in band.high],
    }


def _final(final: Band, auc: Band) -> dict[str, float | None]:
    """The final error with its interval, and the mean error over the learning curve (`auc`)."""
    return {
        "error": finite_or_none(final.mean[0]),
        "ci_low": finite_or_none(final.low[0]),
        "ci_high": finite_or_none(final.high[0]),
        "auc": finite_or_none(auc.mean[0]),
    }


def summary_json(summary: ConfigSummary) -> dict[str, Any]:
    """One configuration as a JSON-ready object."""
    positive = summary.extra.get("positive")
    return {
        "index": summary.index,
        "axes": summary.axes,
        "runs": summary.runs,
        "best": summary.best,
        "diverged": summary.diverged,
        "truth": summary.truth,
        "episodes": summary.episodes,
        **_final(summary.final, summary.auc),
        "auc_low": finite_or_none(summary.auc.low[0]),
        "auc_high": finite_or_none(summary.auc.high[0]),
        "curve": _curve(summary.curve),
        "returns": _curve(summary.returns),
        "positive": _curve(positive) if isinstance(positive, Band) else None,
        "demons": {
            name: {**_final(d.final, d.auc), "curve": _curve(d.curve), "rupee": _curve(d.rupee)}
            for name, d in summary.demons.items()
        },
    }


def results_json(summaries: list[ConfigSummary]) -> list[dict[str, Any]]:
    return [summary_json(s) for s in summaries]


CSV_FIELDS = ("demon", "error", "ci_low", "ci_high", "auc", "auc_low", "auc_high")


def _head(summary: ConfigSummary, paths: list[str]) -> dict[str, Any]:
    """The columns that name a configuration: its index, axis values, runs, best and diverged (0 or 1)."""
    return {"config": summary.index, **{p: summary.axes[p] for p in paths}, "runs": summary.runs,
            "best": int(summary.best), "diverged": int(summary.diverged)}  # fmt: skip


HEAD_FIELDS = ("runs", "best", "diverged")


def results_csv(summaries: list[ConfigSummary]) -> str:
    """One row per configuration and demon (and a row `demon = *` for the relative error over all demons)."""
    paths = list(summaries[0].axes) if summaries else []
    records = []
    for s in summaries:
        head = _head(s, paths)
        rows = [("*", s.final, s.auc)] + [(n, d.final, d.auc) for n, d in s.demons.items()]
        for name, final, auc in rows:
            numbers = (final.mean[0], final.low[0], final.high[0], auc.mean[0], auc.low[0], auc.high[0])
            records.append(
                {**head, "demon": name, **dict(zip(CSV_FIELDS[1:], map(finite_or_none, numbers), strict=True))}
            )
    return to_csv(records, ["config", *paths, *HEAD_FIELDS, *CSV_FIELDS])


CURVE_FIELDS = ("demon", "episode", "error", "ci_low", "ci_high")


def curves_csv(summaries: list[ConfigSummary]) -> str:
    """The learning curves, long format: a row per configuration, demon and checkpoint (`episode`), the mean
    error over runs with its interval; `demon = *` is the relative error over all demons, as in `results_csv`."""
    paths = list(summaries[0].axes) if summaries else []
    records = []
    for s in summaries:
        head = _head(s, paths)
        for name, band in [("*", s.curve), *((n, d.curve) for n, d in s.demons.items())]:
            for episode, mean, low, high in zip(s.episodes, band.mean, band.low, band.high, strict=True):
                numbers = map(finite_or_none, (mean, low, high))
                records.append({**head, "demon": name, "episode": episode,
                                **dict(zip(CURVE_FIELDS[2:], numbers, strict=True))})  # fmt: skip
    return to_csv(records, ["config", *paths, *HEAD_FIELDS, *CURVE_FIELDS])
