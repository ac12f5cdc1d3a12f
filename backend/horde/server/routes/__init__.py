"""One APIRouter per resource, all mounted under /api."""

from fastapi import APIRouter

from horde.server.routes import (
    demons,
    exports,
    health,
    learners,
    overview,
    protocols,
    records,
    runs,
    scenarios,
    snapshots,
    stream,
    studies,
    tokens,
    view,
    worlds,
)

# Each resource's reads (`router`), then its writes (`writes`, which need the token: deps.write_router).
ROUTERS: tuple[APIRouter, ...] = (
    health.router,
    learners.router,
    scenarios.router,
    worlds.router,
    worlds.writes,
    snapshots.router,  # before runs: POST /runs/import must not be taken for a run id
    snapshots.writes,
    runs.router,
    runs.writes,
    demons.router,
    demons.writes,
    stream.router,
    view.router,
    protocols.router,
    protocols.writes,
    studies.router,
    studies.writes,
    exports.router,
    records.router,
    records.writes,
    overview.router,
    tokens.router,
    tokens.writes,
    tokens.me_router,
)

__all__ = ["ROUTERS"]
