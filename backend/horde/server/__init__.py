"""The FastAPI server of Horde Lab: REST under /api, a WebSocket stream per run, persistence in SQLite."""

from horde.server.app import create_app
from horde.server.settings import Settings

__all__ = ["Settings", "create_app"]
