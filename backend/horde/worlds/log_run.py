"""`horde run --log FILE`: a stream world's Horde learning a recorded log at full speed.

The log's records are learned in order, exactly as if a client had pushed them over the WebSocket
(horde.worlds.records), chunk by chunk. Afterwards, the log itself says what happened: for every demon,
the realised discounted return of its question after each record (the behaviour's own return, so it is
the demon's answer only where the target policy is the behaviour's, on-policy) is computed backwards from
the log, and its mean over the records sits beside the mean prediction: the nexting paper's comparison.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from horde.core.questions import Program
from horde.spec import RunSpec, expr_predictions
from horde.worlds.records import RecordLearner, Refusal, log_length, read_log, stream_world

MAX_KEPT = 20_000_000  # predictions x records kept for the realised-return comparison (160 MB)
TAIL_WEIGHT = 1e-3  # records whose remaining return weighs more than this at the log's end are left out


@dataclass
class LogDemon:
    name: str
    prediction: float  # at the log's end
    mean_prediction: float | None  # over the records compared (None: no comparison; nan: no complete return)
    mean_return: float | None  # the realised return, over the same records


@dataclass
class StripWindow:
    """The log's last records: sensors, every demon's prediction and realised return (nan where incomplete)."""

    first: int  # the record number of the window's first row
    sensors: np.ndarray  # [W, S]
    predictions: np.ndarray  # [W, D]
    returns: np.ndarray  # [W, D]


STRIP = 1000  # records in the strip chart's window


@dataclass
class LogResult:
    records: int
    learned: int
    refused: list[Refusal]
    seconds: float
    demons: list[LogDemon] = field(default_factory=list)
    compared: int = 0  # records in the comparison
    window: StripWindow | None = None  # the last records, for the strip chart (None: no comparison)

    @property
    def records_per_second(self) -> float:
        return self.records / self.seconds if self.seconds > 0 else math.nan


def realised_returns(spec: RunSpec, sensors: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """[N, D] realised discounted returns after each record (from the records after it), and [N, D] the
    weight of the part of each return that lies beyond the log's end (the product of continuations)."""
    names = spec.world.sensor_names()
    demons = spec.demons
    program = Program([d.cumulant for d in demons] + [d.outcome for d in demons] + [d.continuation for d in demons],
                      {n: i for i, n in enumerate(names)}, {})  # fmt: skip
    values = program.evaluate(sensors)  # [N, 3D]
    d = len(demons)
    r, z = values[:, :d], values[:, d : 2 * d]
    gamma = np.clip(values[:, 2 * d :], 0.0, 1.0) * np.array([x.discount for x in demons])  # [N, D]
    n = len(sensors)
    returns = np.zeros((n, d))
    tail = np.zeros((n, d))
    g = np.zeros(d)
    w = np.ones(d)
    for t in range(n - 2, -1, -1):  # G_t = r_{t+1} + (1 - gamma_{t+1}) z_{t+1} + gamma_{t+1} G_{t+1}
        g = r[t + 1] + (1.0 - gamma[t + 1]) * z[t + 1] + gamma[t + 1] * g
        w = gamma[t + 1] * w
        returns[t], tail[t] = g, w
    tail[n - 1] = 1.0
    return returns, tail


def learn_log(spec: RunSpec, path: str | Path, progress: Callable[[int, int], None] | None = None) -> LogResult:
    """Learn every record of a CSV or Parquet log in order; compare predictions with realised returns afterwards."""
    path = Path(path)
    world = stream_world(spec)
    learner = RecordLearner(spec)
    total = log_length(path)
    readable = [i for i, d in enumerate(spec.demons)
                if not any(expr_predictions(e) for e in (d.cumulant, d.outcome, d.continuation))]  # fmt: skip
    keep = total * len(spec.demons) <= MAX_KEPT
    refused: list[Refusal] = []
    kept, sensors = [], []
    began = time.perf_counter()
    for records, refusals in read_log(path, world):
        learner.received += len(records) + len(refusals)
        learner.refused += len(refusals)
        refused += refusals
        keep = keep and not refused  # a refused record breaks the stream, and the comparison with it
        out = learner.learn(records, keep_predictions=keep)
        if keep and out is not None:
            kept.append(out)
            sensors.append(records.observations)
        if progress is not None:
            progress(learner.received, total)
    seconds = time.perf_counter() - began
    final = learner.predictions()
    result = LogResult(learner.received, learner.learned, refused, seconds)
    mean_prediction = mean_return = None
    if keep and kept and not refused:
        predictions = np.concatenate(kept)  # [N, D]
        returns, tail = realised_returns(spec, np.concatenate(sensors))
        complete = tail < TAIL_WEIGHT  # [N, D]
        counts = complete.sum(axis=0)
        with np.errstate(invalid="ignore", divide="ignore"):
            mean_prediction = np.where(counts > 0, (predictions * complete).sum(axis=0) / counts, np.nan)
            mean_return = np.where(counts > 0, (returns * complete).sum(axis=0) / counts, np.nan)
        result.compared = int(counts.max()) if len(counts) else 0
        all_sensors = np.concatenate(sensors)
        lo = max(0, len(predictions) - STRIP)
        result.window = StripWindow(lo, all_sensors[lo:], predictions[lo:],
                                    np.where(complete[lo:], returns[lo:], np.nan))  # fmt: skip
    for i, demon in enumerate(spec.demons):
        mine: tuple[float | None, float | None] = (None, None)
        if mean_prediction is not None and mean_return is not None and i in readable:
            mine = (float(mean_prediction[i]), float(mean_return[i]))
        result.demons.append(LogDemon(demon.name, float(final[i]), *mine))
    return result


def format_log_result(path: Path, result: LogResult) -> str:
    """`horde run --log`'s report: throughput, refusals, and per demon its prediction beside its realised return."""

    def number(value: float | None) -> str:
        return "-" if value is None or not math.isfinite(value) else f"{value:.3f}"

    header = ("demon", "prediction now", "mean prediction", "mean realised return", "difference")
    rows = [(d.name, number(d.prediction), number(d.mean_prediction), number(d.mean_return),
             number(None if d.mean_prediction is None or d.mean_return is None else d.mean_prediction - d.mean_return))
            for d in result.demons]  # fmt: skip
    widths = [max(len(r[i]) for r in [header, *rows]) for i in range(len(header))]
    lines = ["  ".join(cell.rjust(w) if i else cell.ljust(w) for i, (cell, w) in enumerate(zip(r, widths, strict=True)))
             for r in [header, *rows]]  # fmt: skip
    lines.insert(1, "  ".join("-" * w for w in widths))
    lines.append("")
    for refusal in result.refused[:10]:
        lines.append(f"refused {refusal.field}: {refusal.message}")
    if len(result.refused) > 10:
        lines.append(f"... and {len(result.refused) - 10} more refused records")
    lines.append(
        f"{path}: {result.records} records, {result.learned} learned, {len(result.refused)} refused, in "
        f"{result.seconds:.2f} s ({result.records_per_second:,.0f} records/s); means over the {result.compared} "
        "records whose realised return the log holds (the behaviour's return: the answer for on-policy demons)"
    )
    return "\n".join(lines)


def strip_chart(spec: RunSpec, result: LogResult, path: Path, sensors: list[str], demons: list[str]) -> None:
    """The nexting figure: the chosen sensors over the log's last records, and each chosen demon's prediction
    beside the realised discounted return computed afterwards from the log (PNG or SVG by the suffix).

    Raises:
        ValueError: no comparison was kept (a refused record, or a log too large), or an unknown name.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    window = result.window
    if window is None:
        raise ValueError("no strip chart: the comparison needs a log without refused records")
    names = spec.world.sensor_names()
    index = {d.name: i for i, d in enumerate(spec.demons)}
    for name in sensors:
        if name not in names:
            raise ValueError(f"--strip-sensors: unknown sensor {name!r} (known: {', '.join(names)})")
    for name in demons:
        if name not in index:
            raise ValueError(f"--strip-demons: unknown demon {name!r}")
    steps = window.first + np.arange(len(window.sensors))
    fig, axes = plt.subplots(1 + len(demons), 1, figsize=(10, 2.2 * (1 + len(demons))), sharex=True)
    axes = np.atleast_1d(axes)
    bounds = spec.world.sensor_bounds()
    for name in sensors:
        values = window.sensors[:, names.index(name)]
        low, high = bounds[name]
        if np.isfinite(low) and np.isfinite(high):  # each on its own range, so that all of them show
            values = (values - low) / (high - low)
        axes[0].plot(steps, values, label=f"{name} [{low:g}, {high:g}]", linewidth=1)
    axes[0].set_ylabel("sensors\n(0-1 of range)", fontsize=8)
    axes[0].legend(loc="upper right", fontsize=8)
    for ax, name in zip(axes[1:], demons, strict=True):
        i = index[name]
        ax.plot(steps, window.predictions[:, i], label="prediction (made at the time)", linewidth=1)
        ax.plot(steps, window.returns[:, i], label="realised return (computed afterwards)", linewidth=1,
                linestyle="--")  # fmt: skip
        ax.set_ylabel(name, fontsize=8)
        ax.legend(loc="upper right", fontsize=8)
    axes[-1].set_xlabel("record")
    fig.suptitle("Each prediction beside the discounted return that followed (the nexting figure)")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
