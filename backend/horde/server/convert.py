"""Run-layer objects (views, histories, evaluations) into the API's output models."""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from datetime import UTC, datetime

import numpy as np

from horde.runs.divergence import MAX_MAGNITUDE, meaningful
from horde.runs.events import Event
from horde.runs.history import Series
from horde.runs.readout import Evaluation, ValueMap
from horde.runs.run_view import RunView, Summary
from horde.server.schemas import (
    AgentOut,
    DemonMetricsOut,
    DemonOut,
    EvaluationOut,
    EventOut,
    HistoryOut,
    RunBriefOut,
    RunOut,
    StateOut,
    SummaryOut,
    ValuesOut,
)
from horde.view.palette import demon_colour


def finite(value: float) -> float | None:
    """The number, or None where it is NaN, infinite or beyond MAX_MAGNITUDE (a diverged demon's)."""
    return meaningful(value)


def predictions(view: RunView) -> np.ndarray:
    """[D] each demon's prediction, NaN (null on the wire) for diverged demons."""
    hs = view.horde_state
    return np.where(hs.diverged, np.nan, hs.prediction)


def finite_list(values: Iterable[float]) -> list[float | None]:
    return [finite(v) for v in values]


def finite_dict(values: dict[str, float]) -> dict[str, float | None]:
    return {k: finite(v) for k, v in values.items()}


def timestamp(seconds: float) -> datetime:
    return datetime.fromtimestamp(seconds, UTC)


def summary_out(summary: Summary) -> SummaryOut:
    return SummaryOut(
        predictions=finite_dict(summary.predictions),
        rupee=finite_dict(summary.rupee),
        ude=finite_dict(summary.ude),
        episodes=summary.episodes,
        steps=summary.steps,
        last_return=finite(summary.last_return),
        stopped_early=summary.stopped_early,
    )


def run_brief(view: RunView) -> RunBriefOut:
    return RunBriefOut(**_brief_fields(view))


def run_out(view: RunView) -> RunOut:
    summary = summary_out(view.summary) if view.summary is not None else None
    return RunOut(**_brief_fields(view), spec=view.spec, summary=summary)


def _brief_fields(view: RunView) -> dict[str, object]:
    return {
        "id": view.id,
        "name": view.spec.name,
        "status": view.status,
        "message": view.message,
        "hz": view.hz,
        "episode": view.episode,
        "step": view.total_steps,
        "demons": list(view.horde.names),
        "created_at": timestamp(view.created_at),
        "updated_at": timestamp(view.updated_at),
    }


def demon_metrics(view: RunView, indices: Sequence[int] | None = None) -> dict[str, DemonMetricsOut]:
    """The metrics of the demons at `indices` (all by default), by name."""
    hs, rupee, ude, names = view.horde_state, view.rupee, view.ude, view.horde.names
    return {
        names[i]: DemonMetricsOut(
            rupee=finite(rupee[i]),
            ude=finite(ude[i]),
            delta=finite(hs.delta[i]),
            cumulant=finite(hs.cumulant[i]),
            diverged=bool(hs.diverged[i]),
            step_size=finite(view.step_size[i]) if view.step_size is not None else None,
        )
        for i in (range(len(names)) if indices is None else indices)
    }


def event_out(event: Event) -> EventOut:
    value = finite(event.value) if event.value is not None else None
    return EventOut(
        seq=event.seq,
        step=event.step,
        episode=event.episode,
        kind=event.kind,
        message=event.message,
        value=value,
    )


def state_out(view: RunView, events: list[Event], demons: Sequence[int] | None = None) -> StateOut:
    """The run's state with the predictions and metrics of the demons at `demons` (all by default)."""
    x, y = view.position
    names, prediction = view.horde.names, predictions(view)
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
        episode_return=finite(view.episode_return),
        last_return=finite(view.last_return),
        predictions={names[i]: finite(prediction[i]) for i in indices},
        metrics=demon_metrics(view, indices),
        demon_total=len(names),
        events=[event_out(e) for e in events],
    )


def demons_out(view: RunView) -> list[DemonOut]:
    metrics = demon_metrics(view)
    prediction = predictions(view)
    return [
        DemonOut(
            name=spec.name,
            spec=spec,
            control=view.horde.is_control(spec.name),
            prediction=finite(prediction[view.horde.index[spec.name]]),
            metrics=metrics[spec.name],
            colour=demon_colour(i),
        )
        for i, spec in enumerate(view.horde.demon_specs)
    ]


def values_out(view: RunView, demon: str, values: ValueMap) -> ValuesOut:
    """A demon's value map; all null when the demon has diverged."""
    diverged = bool(view.horde_state.diverged[view.horde.index[demon]])
    grid = np.full_like(values.values, np.nan) if diverged else values.values
    finite_cells = grid[np.abs(grid) <= MAX_MAGNITUDE]
    return ValuesOut(
        demon=demon,
        resolution=len(values.xs),
        width=view.spec.world.width,
        height=view.spec.world.height,
        x=values.xs.tolist(),
        y=values.ys.tolist(),
        values=[finite_list(row) for row in grid],
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
        prediction=finite_list(v["prediction"]),
        cumulant=finite_list(v["cumulant"]),
        delta=finite_list(v["delta"]),
        rupee=finite_list(v["rupee"]),
        ude=finite_list(v["ude"]),
    )


def evaluation_out(evaluation: Evaluation) -> EvaluationOut:
    truth = evaluation.truth
    return EvaluationOut(
        demon=evaluation.demon,
        from_=list(evaluation.start),
        prediction=finite(evaluation.prediction),
        truth=finite(truth.mean),
        stderr=finite(truth.stderr),
        error=finite(evaluation.prediction - truth.mean),
        episodes=truth.rollouts,
        cap=truth.cap,
        capped=truth.capped,
        seed=evaluation.seed,
        exact=finite(evaluation.exact) if evaluation.exact is not None else None,
    )
