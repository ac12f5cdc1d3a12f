"""Means over independent runs with 95 % percentile-bootstrap confidence intervals, and study summaries.

The bootstrap (Efron 1979): draw the runs with replacement `resamples` times, take the mean of each draw,
and report the 2.5 % and 97.5 % quantiles of those means. It assumes nothing about the errors'
distribution, which is skewed for RMSE near zero. Its width shrinks like 1/sqrt(runs); with one run it is
a single point (no spread can be seen), which the summaries report as it is. Resampling is seeded, so the
same results give the same bands.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np

from horde.studies.spec import AxisValue
from horde.studies.task import TaskData

LEVEL = 0.95
RESAMPLES = 2000


def bootstrap_mean(
    samples: np.ndarray, level: float = LEVEL, resamples: int = RESAMPLES, seed: int = 0
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Mean over the first axis and its percentile-bootstrap confidence interval.

    Args:
        samples: [R, ...] one row per independent run (nan rows are left out per column).
        level: the interval's coverage.
        resamples: bootstrap draws.
        seed: of the resampling generator.

    Returns:
        (mean, low, high), each [...].
    """
    samples = np.asarray(samples, dtype=float)
    runs = samples.shape[0]
    if runs == 0:
        raise ValueError("no runs to average")
    rng = np.random.default_rng(seed)
    draws = rng.integers(0, runs, size=(resamples, runs))  # [B, R]
    with warnings.catch_warnings():  # an all-nan column (a diverged demon in every run) stays nan
        warnings.simplefilter("ignore", RuntimeWarning)
        mean = np.nanmean(samples, axis=0)  # [...]
        means = np.nanmean(samples[draws], axis=1)  # [B, ...]
        tail = (1.0 - level) / 2.0
        low, high = np.nanquantile(means, [tail, 1.0 - tail], axis=0)
    return mean, low, high


@dataclass
class Band:
    """A mean over runs with its confidence interval, per checkpoint or as one number."""

    mean: list[float]
    low: list[float]
    high: list[float]

    @classmethod
    def of(cls, samples: np.ndarray) -> Band:
        mean, low, high = bootstrap_mean(samples)
        return cls(*(np.atleast_1d(a).tolist() for a in (mean, low, high)))


@dataclass
class DemonSummary:
    """One demon of one configuration, over its runs."""

    curve: Band  # error per checkpoint
    final: Band  # error at the last checkpoint
    auc: Band  # mean error over the checkpoints after episode 0 (the area under the learning curve)
    rupee: Band  # per checkpoint


@dataclass
class ConfigSummary:
    """One configuration over its runs: per demon, and all demons together as relative errors."""

    index: int
    axes: dict[str, AxisValue]
    runs: int
    episodes: list[int]
    truth: str
    demons: dict[str, DemonSummary]
    curve: Band  # mean over demons of error / scale, per checkpoint
    final: Band
    auc: Band
    returns: Band
    best: bool = False
    seconds: float = 0.0
    extra: dict[str, object] = field(default_factory=dict)


def summarize_configuration(index: int, axes: dict[str, AxisValue], tasks: list[TaskData]) -> ConfigSummary:
    """Average a configuration's finished runs (at least one) into bands."""
    episodes = tasks[0]["episodes"]
    names = list(tasks[0]["demons"])
    demons = {}
    relative = []
    for name in names:
        error = np.array([t["demons"][name]["error"] for t in tasks])  # [R, C]
        scale = np.array([t["demons"][name]["scale"] for t in tasks])  # [R, C]
        rupee = np.array([t["demons"][name]["rupee"] for t in tasks])  # [R, C]
        demons[name] = DemonSummary(Band.of(error), Band.of(error[:, -1]), Band.of(_area(error)), Band.of(rupee))
        relative.append(error / np.where(scale > 0, scale, 1.0))
    rel = np.mean(relative, axis=0)  # [R, C]
    returns = np.array([t["returns"] for t in tasks])  # [R, C]
    extra: dict[str, object] = {}
    if all("counts" in t for t in tasks):  # the share of test runs ending in a positive terminal
        shares = np.array([t["counts"]["positive"] / max(1, sum(t["counts"].values())) for t in tasks])  # [R]
        extra["positive"] = Band.of(shares)
    return ConfigSummary(
        index=index,
        axes=axes,
        runs=len(tasks),
        episodes=episodes,
        truth=tasks[0]["truth"],
        demons=demons,
        curve=Band.of(rel),
        final=Band.of(rel[:, -1]),
        auc=Band.of(_area(rel)),
        returns=Band.of(returns),
        seconds=float(sum(t["seconds"] for t in tasks)),
        extra=extra,
    )


def _area(curves: np.ndarray) -> np.ndarray:
    """[R, C] -> [R]: the mean over the checkpoints after the first (before learning, the same for all)."""
    return curves[:, 1:].mean(axis=1) if curves.shape[1] > 1 else curves[:, 0]


def mark_best(summaries: list[ConfigSummary]) -> None:
    """Mark the configuration with the lowest final relative error (ties: the first)."""
    finite = [s for s in summaries if np.isfinite(s.final.mean[0])]
    for s in summaries:
        s.best = False
    if finite:
        min(finite, key=lambda s: s.final.mean[0]).best = True
