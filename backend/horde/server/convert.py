"""Run-layer objects (views, histories, evaluations) into the API's output models.

Objects whose attributes are the model's fields are validated as they are
(`model_validate(obj, from_attributes=True)`); the others name the fields they fill. Either way the
models' `MaybeFloat` fields turn NaN, infinities and diverged numbers into null, so nothing here
filters numbers one by one.
"""

from __future__ import annotations

from collections.abc import Sequence
from datetime import UTC, datetime
from typing import cast

import numpy as np

from horde.runs.divergence import MAX_MAGNITUDE
from horde.runs.events import Event
from horde.runs.history import Series
from horde.runs.readout import Evaluation, ValueMap, evaluation_support
from horde.runs.run_view import RunView, Summary
from horde.server.schemas import (
    AgentOut,
    DemonMetricsOut,
    DemonOut,
    EvaluationOut,
    EvaluationSupportOut,
    EventOut,
    HistoryOut,
    RunBriefOut,
    RunOut,
    StateOut,
    SummaryOut,
    ValuesOut,
    WorkerOut,
)
from horde.view.palette import demon_colour


def predictions(view: RunView) -> np.ndarray:
    """[D] each demon's prediction, NaN (null on the wire) for diverged demons."""
    return np.where(view.diverged, np.nan, view.prediction)


def timestamp(seconds: float) -> datetime:
    return datetime.fromtimestamp(seconds, UTC)


def summary_out(summary: Summary) -> SummaryOut:
    return SummaryOut.model_validate(summary, from_attributes=True)


def run_brief(view: RunView, owner: str) -> RunBriefOut:
    return RunBriefOut(**_brief_fields(view, owner))


def run_out(view: RunView, owner: str) -> RunOut:
    summary = summary_out(view.summary) if view.summary is not None else None
    return RunOut(**_brief_fields(view, owner), spec=view.spec, summary=summary)


def _brief_fields(view: RunView, owner: str) -> dict[str, object]:
    return {
        "id": view.id,
        "owner": owner,
        "name": view.spec.name,
        "status": view.status,
        "message": view.message,
        "hz": view.hz,
        "episode": view.episode,
        "step": view.total_steps,
        "demons": view.names,
        "evaluation": EvaluationSupportOut.model_validate(evaluation_support(view.spec), from_attributes=True),
        "worker": WorkerOut.model_validate(view.worker, from_attributes=True),
        "created_at": timestamp(view.created_at),
        "updated_at": timestamp(view.updated_at),
    }


def demon_metrics(view: RunView, indices: Sequence[int] | None = None) -> dict[str, DemonMetricsOut]:
    """The metrics of the demons at `indices` (all by default), by name."""
    rupee, ude, names = view.rupee, view.ude, view.names
    return {
        names[i]: DemonMetricsOut(
            rupee=rupee[i],
            ude=ude[i],
            delta=view.delta[i],
            cumulant=view.cumulant[i],
            diverged=bool(view.diverged[i]),
            step_size=view.step_size[i] if view.step_size is not None else None,
        )
        for i in (range(len(names)) if indices is None else indices)
    }


def event_out(event: Event) -> EventOut:
    return EventOut.model_validate(event, from_attributes=True)


def state_out(view: RunView, events: list[Event], demons: Sequence[int] | None = None) -> StateOut:
    """The run's state with the predictions and metrics of the demons at `demons` (all by default)."""
    x, y = view.position
    names, prediction = view.names, predictions(view)
    indices = range(len(names)) if demons is None else demons
    return StateOut(
        run=view.id,
        status=view.status,
        message=view.message,
        hz=view.hz,
        agent=AgentOut(x=x, y=y),
        episode=view.episode,
        step=view.total_steps,
        episode_step=view.episode_step,
        episode_return=view.episode_return,
        last_return=view.last_return,
        predictions={names[i]: prediction[i] for i in indices},
        metrics=demon_metrics(view, indices),
        demon_total=len(names),
        events=[event_out(e) for e in events],
        sensors=None
        if view.sensors is None
        else dict(zip(view.spec.world.sensor_names(), view.sensors.tolist(), strict=True)),
    )


def demons_out(view: RunView) -> list[DemonOut]:
    metrics = demon_metrics(view)
    prediction = predictions(view)
    return [
        DemonOut(
            name=spec.name,
            spec=spec,
            control=bool(view.control[i]),
            prediction=prediction[i],
            metrics=metrics[spec.name],
            colour=demon_colour(i),
        )
        for i, spec in enumerate(view.spec.demons)
    ]


def state_values_out(view: RunView, demon: str, report: dict[str, object]) -> ValuesOut:
    """A demon's prediction at every state of a world with known transitions (`readout.state_values`); its values
    null when the demon has diverged."""
    diverged = bool(view.diverged[view.index[demon]])
    states = cast(list[float], report["states"])
    values = np.full(len(states), np.nan) if diverged else np.asarray(report["values"], dtype=float)
    finite = values[np.abs(values) <= MAX_MAGNITUDE]
    truths = {k: report.get(k) for k in ("exact", "fixed_point", "rmsve", "rms_error", "rmspbe", "weighting")}
    if diverged:
        truths.update(rmsve=None, rms_error=None, rmspbe=None)
    return ValuesOut(
        kind="states",
        demon=demon,
        resolution=len(states),
        width=float(len(states)),
        height=1.0,
        x=[float(s) for s in states],
        y=[],
        values=[values.tolist()],
        min=float(finite.min()) if finite.size else None,
        max=float(finite.max()) if finite.size else None,
        **truths,
    )


def values_out(view: RunView, demon: str, values: ValueMap) -> ValuesOut:
    """A demon's value map; all null when the demon has diverged."""
    diverged = bool(view.diverged[view.index[demon]])
    grid = np.full_like(values.values, np.nan) if diverged else values.values
    finite_cells = grid[np.abs(grid) <= MAX_MAGNITUDE]
    return ValuesOut(
        demon=demon,
        resolution=len(values.xs),
        width=view.spec.grid.width,
        height=view.spec.grid.height,
        x=values.xs.tolist(),
        y=values.ys.tolist(),
        values=grid.tolist(),
        min=float(finite_cells.min()) if finite_cells.size else None,
        max=float(finite_cells.max()) if finite_cells.size else None,
    )


def history_out(demon: str, series: Series, every: int, capacity: int) -> HistoryOut:
    v = series.values
    return HistoryOut(
        demon=demon,
        every=every,
        capacity=capacity,
        step=series.steps.tolist(),
        prediction=v["prediction"].tolist(),
        cumulant=v["cumulant"].tolist(),
        delta=v["delta"].tolist(),
        rupee=v["rupee"].tolist(),
        ude=v["ude"].tolist(),
        rmsve=v["rmsve"].tolist() if "rmsve" in v else None,
        rmspbe=v["rmspbe"].tolist() if "rmspbe" in v else None,
    )


def evaluation_out(evaluation: Evaluation) -> EvaluationOut:
    truth = evaluation.truth
    return EvaluationOut(
        demon=evaluation.demon,
        from_=list(evaluation.start),
        prediction=evaluation.prediction,
        truth=truth.mean,
        stderr=truth.stderr,
        error=evaluation.prediction - truth.mean,
        episodes=truth.rollouts,
        cap=truth.cap,
        capped=truth.capped,
        seed=evaluation.seed,
        step=evaluation.step,
        exact=evaluation.exact,
    )
