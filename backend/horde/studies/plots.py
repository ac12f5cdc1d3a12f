"""Static figures of a study for papers (matplotlib, PNG and SVG): learning curves and sensitivity curves.

- `learning-curves`: relative error (mean over the measured demons of error / scale, see `task.py`)
  against training episodes, the mean over runs with its 95 % bootstrap band, one line per configuration
  (past `MAX_LINES`, the best configuration of each value of the grouping axis).
- `sensitivity-final`, `sensitivity-auc`: the final error, or its mean over the learning curve, against one
  swept axis (`x`), one curve per value of another (`group`); where further axes were swept, each point is
  the best configuration over them. Error bars are the 95 % bootstrap intervals.

A diverged configuration (`ConfigSummary.diverged`) is drawn but marked: a dotted line, or a red cross at the
top edge, "(diverged)" in the legend, and a note under the title. The y axis is scaled to the configurations
that did not diverge, so one error of 1e9 does not flatten every other curve to the bottom.
"""

from __future__ import annotations

import math
import textwrap
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import cast

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib import ticker

from horde.studies.spec import AxisValue, label
from horde.studies.stats import Band, ConfigSummary

MAX_LINES = 8
YLABEL = "relative error (RMSE / RMS of the exact answers)"
DIVERGED_NOTE = "diverged configurations dotted or \u00d7 at the top, left out of the y scale"
MARGIN = 1.5  # the y axis reaches this factor beyond the lowest and highest value shown (log scale)


def _scale_to(ax: plt.Axes, values: Iterable[float]) -> float | None:
    """Fit the log y axis to these values (the configurations that did not diverge); returns its top."""
    shown = [v for v in values if math.isfinite(v) and v > 0]
    if not shown:
        return None
    low, high = min(shown) / MARGIN, max(shown) * MARGIN
    ax.set_ylim(low, high)
    return high


def _numeric(values: Sequence[AxisValue]) -> bool:
    return all(isinstance(v, int | float) and not isinstance(v, bool) for v in values)


def choose_axes(
    summaries: list[ConfigSummary], x: str | None = None, group: str | None = None
) -> tuple[str, str | None]:
    """The axis along the sensitivity plot (default: the first numeric one that varies) and the grouping one
    (default: the last other axis that varies)."""
    paths = list(summaries[0].axes)
    varying = [p for p in paths if len({repr(s.axes[p]) for s in summaries}) > 1] or paths
    if x is None:
        numeric = [p for p in varying if _numeric([s.axes[p] for s in summaries])]
        x = numeric[0] if numeric else varying[0]
    if group is None:
        others = [p for p in varying if p != x]
        group = others[-1] if others else None
    for name in (x, group):
        if name is not None and name not in paths:
            raise ValueError(f"{name!r} is not an axis of this study (axes: {', '.join(paths)})")
    return x, group


def _best_by(summaries: list[ConfigSummary], keys: Sequence[str | None], metric: str) -> dict[tuple, ConfigSummary]:
    best: dict[tuple, ConfigSummary] = {}
    for s in summaries:
        key = tuple(repr(s.axes[k]) if k else None for k in keys)
        value = getattr(s, metric).mean[0]
        if key not in best or value < getattr(best[key], metric).mean[0]:
            best[key] = s
    return best


def learning_curves(summaries: list[ConfigSummary], group: str | None, path: Path) -> None:
    shown = summaries
    title = "Learning curves: mean over runs, 95\u00a0% bootstrap band"
    if len(summaries) > MAX_LINES:
        shown = list(_best_by(summaries, [group], "final").values())[:MAX_LINES]
        title += f"\nbest configuration per {group.split('.')[-1] if group else 'study'}"
    if any(s.diverged for s in shown):
        title += f"\n{DIVERGED_NOTE}"
    fig, ax = plt.subplots(figsize=(7, 4.2))
    for s in shown:
        name = (label(s.axes) or "the base") + ("  (best)" if s.best and len(shown) > 1 else "")
        name += "  (diverged)" if s.diverged else ""
        style = ":" if s.diverged else "-"
        (line,) = ax.plot(s.episodes, s.curve.mean, label=f"{name}, {s.runs} runs", linestyle=style)
        if not s.diverged:
            ax.fill_between(s.episodes, s.curve.low, s.curve.high, color=line.get_color(), alpha=0.2, linewidth=0)
    ax.set_xlabel("training episodes")
    ax.set_ylabel(YLABEL)
    ax.set_yscale("log")
    _scale_to(ax, (v for s in shown if not s.diverged for v in (*s.curve.low, *s.curve.high, *s.curve.mean)))
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    _save(fig, path)


def sensitivity(summaries: list[ConfigSummary], x: str, group: str | None, metric: str, path: Path) -> None:
    """`metric`: "final" or "auc"."""
    best = _best_by(summaries, [x, group], metric)
    groups = sorted({k[1] for k in best}, key=str)
    fig, ax = plt.subplots(figsize=(7, 4.2))
    xs_all = [s.axes[x] for s in summaries]
    numeric = _numeric(xs_all)
    order = sorted({repr(v): v for v in xs_all}.values(), key=lambda v: v if numeric else str(v))
    ax.set_yscale("log")
    bands = [getattr(p, metric) for p in best.values() if not p.diverged]
    top = _scale_to(ax, (v for band in bands for v in (band.mean[0], band.low[0], band.high[0])))
    crosses: list[AxisValue] = []  # where the diverged configurations are, along x
    for g in groups:
        points = [best[(repr(v), g)] for v in order if (repr(v), g) in best]
        crosses += [p.axes[x] if numeric else order.index(p.axes[x]) for p in points if p.diverged]
        points = [p for p in points if not p.diverged]
        xs = [p.axes[x] if numeric else order.index(p.axes[x]) for p in points]
        mean = [getattr(p, metric).mean[0] for p in points]
        low = [m - getattr(p, metric).low[0] for m, p in zip(mean, points, strict=True)]
        high = [getattr(p, metric).high[0] - m for m, p in zip(mean, points, strict=True)]
        name = f"{group.split('.')[-1]}={g}" if group else "all"
        ax.errorbar(xs, mean, yerr=[low, high], marker="o", capsize=3, label=name)
    if crosses:
        edge = top if top is not None else 1.0
        ax.plot(crosses, [edge] * len(crosses), "x", color="red", markersize=10, clip_on=False, label="diverged")
    positive = [float(v) for v in order if numeric and float(v) > 0]
    if numeric and len(positive) == len(order) and max(positive) / min(positive) >= 10:
        ax.set_xscale("log")
    if not numeric:
        ax.set_xticks(range(len(order)), [str(v) for v in order])
    else:
        ax.set_xticks([float(v) for v in order], [f"{float(v):g}" for v in order])
        ax.xaxis.set_minor_locator(ticker.NullLocator())
    ax.set_xlabel(x)
    ax.set_ylabel(("final " if metric == "final" else "mean over training: ") + YLABEL, fontsize=8)
    rest = [p for p in summaries[0].axes if p not in (x, group)]
    note = f" (best over {', '.join(rest)})" if rest else ""
    title = textwrap.fill(f"Sensitivity to {x}{note}; 95\u00a0% bootstrap intervals", 80)
    ax.set_title(title + (f"\n{DIVERGED_NOTE}" if crosses else ""), fontsize=9)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    _save(fig, path)


def _plain_numbers(ax: plt.Axes) -> None:
    """0.2, 0.3, 0.5 on log axes rather than 2 x 10^-1; minor ticks labelled only on a short y axis."""
    plain = ticker.FuncFormatter(lambda v, _: f"{v:g}")
    for axis, limits in ((ax.xaxis, ax.get_xlim()), (ax.yaxis, ax.get_ylim())):
        if axis.get_scale() != "log":
            continue
        axis.set_major_formatter(plain)
        short = axis is ax.yaxis and limits[0] > 0 and limits[1] / limits[0] < 30
        axis.set_minor_formatter(plain if short else ticker.NullFormatter())


def state_values(summaries: list[ConfigSummary], path: Path) -> None:
    """Every state's final value (a world with known transitions): the mean over runs with its 95 % band, one line
    per configuration and measured demon (at most MAX_LINES), and the exact values in black (the book's figures
    9.1 and 9.2)."""
    fig, ax = plt.subplots(figsize=(7, 4.2))
    shown = 0
    states = cast(list[int], summaries[0].extra["states"])
    for s in summaries:
        bands = cast(dict[str, Band], s.extra["values"])
        for name, band in bands.items():
            if shown >= MAX_LINES:
                break
            shown += 1
            tag = (label(s.axes) + " " if s.axes else "") + (name if len(bands) > 1 else "")
            (line,) = ax.plot(states, band.mean, label=f"{tag.strip() or 'prediction'}, {s.runs} runs", linewidth=1.2)
            ax.fill_between(states, band.low, band.high, color=line.get_color(), alpha=0.25, linewidth=0)
    exact = summaries[0].extra["exact"]
    assert isinstance(exact, dict)
    ax.plot(states, cast(list[float], next(iter(exact.values()))), color="black", linewidth=1.0, label="true values")
    ax.set_xlabel("state")
    ax.set_ylabel("value after training")
    ax.set_title("Every state's value: mean over runs, 95\u00a0% bootstrap band; the truth in black", fontsize=10)
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    _save(fig, path)


def _caption(fig: plt.Figure, caption: str) -> None:
    """The study's caption under the figure (the figure grows to hold it)."""
    if not caption:
        return
    text = textwrap.fill(caption, 110)
    lines = text.count("\n") + 1
    width, height = fig.get_size_inches()
    extra = 0.16 * lines + 0.2
    fig.set_size_inches(width, height + extra)
    fig.tight_layout(rect=(0, extra / (height + extra), 1, 1))
    fig.text(0.01, 0.01, text, fontsize=7, va="bottom", ha="left", wrap=False)


CAPTION = ""  # the study's caption, set by write_plots for every figure it draws


def _save(fig: plt.Figure, path: Path) -> None:
    for ax in fig.axes:
        _plain_numbers(ax)
    fig.tight_layout()
    _caption(fig, CAPTION)
    for suffix in (".png", ".svg"):
        fig.savefig(path.with_suffix(suffix), dpi=120)
    plt.close(fig)


def write_plots(
    summaries: list[ConfigSummary],
    directory: Path,
    x: str | None = None,
    group: str | None = None,
    caption: str = "",
) -> list[Path]:
    """Write every figure into `directory`, each with the study's caption under it; return the files written."""
    global CAPTION
    directory.mkdir(parents=True, exist_ok=True)
    CAPTION = caption
    stems = ["learning-curves"]
    try:
        if "values" in summaries[0].extra:  # a world with known transitions: every state's value (figures 9.1, 9.2)
            state_values(summaries, directory / "values")
            stems.append("values")
        if not summaries[0].axes or all(len({repr(s.axes[p]) for s in summaries}) == 1 for p in summaries[0].axes):
            learning_curves(summaries, None, directory / "learning-curves")  # one configuration: its curve
        else:
            x, group = choose_axes(summaries, x, group)
            learning_curves(summaries, group, directory / "learning-curves")
            sensitivity(summaries, x, group, "final", directory / "sensitivity-final")
            sensitivity(summaries, x, group, "auc", directory / "sensitivity-auc")
            stems += ["sensitivity-final", "sensitivity-auc"]
    finally:
        CAPTION = ""
    return [directory / f"{stem}{suffix}" for stem in stems for suffix in (".png", ".svg")]
