"""GET /api/overview: every run of the server as a small card (the dashboard's Class tab, polled).

A card names the run, its owner, status and counters, and carries a sparkline of its first demons'
predictions over the history the run keeps, thinned to `SPARK_POINTS` points: a teacher sees a room of
experiments at a glance without fetching thirty histories.
"""

from __future__ import annotations

import numpy as np
from fastapi import APIRouter

from horde.runs.errors import NotFoundError
from horde.runs.live_run import LiveRun
from horde.server.class_schemas import RunCardOut, SparklineOut
from horde.server.convert import timestamp
from horde.server.deps import AccessDep, ManagerDep

router = APIRouter(prefix="/overview", tags=["classroom"])

SPARK_DEMONS = 3  # the first demons of each run
SPARK_POINTS = 48  # points of each sparkline at most


def sparkline(run: LiveRun, demons: int = SPARK_DEMONS, points: int = SPARK_POINTS) -> SparklineOut:
    """The first `demons` demons' predictions over the run's kept history, at most `points` rows of it, evenly
    spread from the oldest to the newest."""
    steps = np.zeros(0, dtype=np.int64)
    series: dict[str, list[float | None]] = {}
    for name in run.view.names[:demons]:
        try:
            rows = run.history.series(name)
        except KeyError:  # the demon left the run meanwhile
            continue
        keep = np.unique(np.linspace(0, len(rows.steps) - 1, min(points, len(rows.steps))).round().astype(int))  # [P]
        steps = rows.steps[keep]
        series[name] = rows.values["prediction"][keep].tolist()
    return SparklineOut(steps=steps.tolist(), series=series)


@router.get("", summary="Every run as a card: owner, status, counters, a sparkline of its first demons")
def overview(manager: ManagerDep, access: AccessDep) -> list[RunCardOut]:
    runs = []
    for view in sorted(manager.list(), key=lambda v: v.created_at):
        try:
            run = manager.get(view.id)
        except NotFoundError:  # deleted meanwhile
            continue
        runs.append(
            RunCardOut(
                id=view.id,
                name=view.spec.name,
                owner=access.owner_name("run", view.id),
                status=view.status,
                episode=view.episode,
                step=view.total_steps,
                sparkline=sparkline(run),
                updated_at=timestamp(view.updated_at),
            )
        )
    return runs
