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
# A run whose final relative error or its mean over the learning curve (AUC) is non-finite or beyond this has
# diverged: no fit is a million times worse than the answer's own size, while a diverging learner's error grows
# tenfold every few hundred steps and passes it long before the engine freezes the demon (at 1e12).
DIVERGED_ERROR = 1e6


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
        flat_samples = samples.reshape(runs, -1)  # [R, K]
        gaps = np.isnan(flat_samples).any(axis=0)  # [K]: nanmean only where needed (it copies)
        flat_means = np.empty((resamples, flat_samples.shape[1]))  # [B, K]
        flat_means[:, ~gaps] = flat_samples[:, ~gaps][draws].mean(axis=1)
        if gaps.any():
            flat_means[:, gaps] = np.nanmean(flat_samples[:, gaps][draws], axis=1)
        means = flat_means.reshape(resamples, *samples.shape[1:])  # [B, ...]
        tail = (1.0 - level) / 2.0
        flat = means.reshape(resamples, -1)  # [B, K]
        bounds = np.empty((2, flat.shape[1]))  # [2, K]
        holes = np.isnan(flat).any(axis=0)  # [K]: nanquantile only where needed (it is slow)
        bounds[:, ~holes] = np.quantile(flat[:, ~holes], [tail, 1.0 - tail], axis=0)
        if holes.any():
            bounds[:, holes] = np.nanquantile(flat[:, holes], [tail, 1.0 - tail], axis=0)
        low, high = (b.reshape(means.shape[1:]) for b in bounds)
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
    diverged: bool = False  # a run diverged: an error non-finite or beyond DIVERGED_ERROR, or a demon frozen
    best: bool = False
    seconds: float = 0.0
    extra: dict[str, object] = field(default_factory=dict)


class _Columns:
    """Samples of one configuration gathered as columns of one [R, K] matrix, so that a single bootstrap
    (the same resampled runs for every column, as separate calls with the same seed would draw) gives
    every band at once."""

    def __init__(self, runs: int) -> None:
        self.runs = runs
        self.parts: list[np.ndarray] = []
        self.width = 0
        self.result: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None

    def add(self, samples: np.ndarray) -> slice:
        """Add [R] or [R, C] samples; returns where their columns are."""
        part = np.asarray(samples, dtype=float).reshape(self.runs, -1)  # [R, C]
        self.parts.append(part)
        self.width += part.shape[1]
        return slice(self.width - part.shape[1], self.width)

    def band(self, where: slice) -> Band:
        if self.result is None:
            self.result = bootstrap_mean(np.concatenate(self.parts, axis=1))
        mean, low, high = self.result
        return Band(mean[where].tolist(), low[where].tolist(), high[where].tolist())


def summarize_configuration(index: int, axes: dict[str, AxisValue], tasks: list[TaskData]) -> ConfigSummary:
    """Average a configuration's finished runs (at least one) into bands."""
    episodes = tasks[0]["episodes"]
    names = list(tasks[0]["demons"])
    columns = _Columns(len(tasks))
    where: dict[str, tuple[slice, slice, slice, slice]] = {}
    relative = []
    for name in names:
        error = np.array([t["demons"][name]["error"] for t in tasks])  # [R, C]
        scale = np.array([t["demons"][name]["scale"] for t in tasks])  # [R, C]
        rupee = np.array([t["demons"][name]["rupee"] for t in tasks])  # [R, C]
        where[name] = (columns.add(error), columns.add(error[:, -1]), columns.add(_area(error)), columns.add(rupee))
        relative.append(error / np.where(scale > 0, scale, 1.0))
    rel = np.mean(relative, axis=0)  # [R, C]
    per_run = np.concatenate([rel[:, -1], _area(rel)])  # [2R] each run's final error and AUC
    diverged = bool((~np.isfinite(per_run) | (np.abs(per_run) > DIVERGED_ERROR)).any())
    diverged = diverged or any(t.get("diverged") for t in tasks)  # the engine froze a measured demon
    returns = np.array([t["returns"] for t in tasks])  # [R, C]
    overall = (columns.add(rel), columns.add(rel[:, -1]), columns.add(_area(rel)), columns.add(returns))
    positive = None
    if all("counts" in t for t in tasks):  # the share of test runs ending in a positive terminal
        shares = np.array([t["counts"]["positive"] / max(1, sum(t["counts"].values())) for t in tasks])  # [R]
        positive = columns.add(shares)
    demons = {name: DemonSummary(*(columns.band(w) for w in where[name])) for name in names}
    curve, final, auc, returns_band = (columns.band(w) for w in overall)
    return ConfigSummary(
        index=index,
        axes=axes,
        runs=len(tasks),
        episodes=episodes,
        truth=tasks[0]["truth"],
        demons=demons,
        curve=curve,
        final=final,
        auc=auc,
        returns=returns_band,
        diverged=diverged,
        seconds=float(sum(t["seconds"] for t in tasks)),
        extra=({"positive": columns.band(positive)} if positive is not None else {}) | _state_values(tasks),
    )


def _state_values(tasks: list[TaskData]) -> dict[str, object]:
    """Tasks on a world with known transitions (`chain_task.py`): every state's final value per demon, the mean
    over runs with its band, beside the exact values."""
    if not all("values" in t for t in tasks):
        return {}
    names = list(tasks[0]["values"])
    bands = {name: Band.of(np.array([t["values"][name] for t in tasks])) for name in names}
    return {"states": tasks[0]["states"], "values": bands, "exact": tasks[0]["exact"]}


def _area(curves: np.ndarray) -> np.ndarray:
    """[R, C] -> [R]: the mean over the checkpoints after the first (before learning, the same for all)."""
    return curves[:, 1:].mean(axis=1) if curves.shape[1] > 1 else curves[:, 0]


def mark_best(summaries: list[ConfigSummary]) -> None:
    """Mark the configuration with the lowest final relative error (ties: the first); never a diverged one."""
    finite = [s for s in summaries if np.isfinite(s.final.mean[0]) and not s.diverged]
    for s in summaries:
        s.best = False
    if finite:
        min(finite, key=lambda s: s.final.mean[0]).best = True
