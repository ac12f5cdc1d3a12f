"""One APIRouter per resource, all mounted under /api."""

from fastapi import APIRouter

from horde.server.routes import (
    demons,
    exports,
    health,
    protocols,
    records,
    runs,
    scenarios,
    snapshots,
    stream,
    studies,
    view,
    worlds,
)

ROUTERS: tuple[APIRouter, ...] = (
    health.router,
    scenarios.router,
    worlds.router,
    snapshots.router,  # before runs: POST /runs/import must not be taken for a run id
    runs.router,
    demons.router,
    stream.router,
    view.router,
    protocols.router,
    studies.router,
    exports.router,
    records.router,
)

__all__ = ["ROUTERS"]
