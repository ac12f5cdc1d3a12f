"""The FastAPI application factory.

`create_app(settings)` builds the app; its `lifespan` opens the store, starts the run manager (which
loads the stored runs) and sets the interpreter's GIL switch interval (HORDE_SWITCH_INTERVAL, short
so that the event loop gets the GIL soon while learner threads compute); on the way out it stops the
streams and every learner thread (running runs are saved as paused) and closes the store. Tests build
the app with their own settings (a temporary data directory) and enter the lifespan with
`TestClient(app)` as a context manager, once at a time. Routes reach what the lifespan made through
the dependencies of `horde.server.deps`, the only readers of `app.state`. The viser live view starts
only when `settings.viser_port` is set (`horde serve` sets it), so tests leave it out unless they ask
for it. The built dashboard is served at `/`.
"""

from __future__ import annotations

import gc
import sys
from collections.abc import AsyncIterator, Callable
from contextlib import AbstractAsyncContextManager, asynccontextmanager

from fastapi import FastAPI

from horde.runs.access import Access
from horde.runs.executor import ProcessExecutor
from horde.runs.link import Executor
from horde.runs.manager import RunManager
from horde.runs.protocols import ProtocolJobs
from horde.runs.ray_link import RayExecutor
from horde.runs.store import Store
from horde.runs.stream_run import StreamRuns
from horde.server.api_docs import add_api_docs
from horde.server.catalog import ScenarioCatalog
from horde.server.frontend import DIST_DIR, mount_frontend
from horde.server.guard import BodyGuard, validate_off_loop
from horde.server.hosts import HostGuard
from horde.server.origins import origin_allowed
from horde.server.responses import add_error_handlers
from horde.server.routes import ROUTERS
from horde.server.settings import Settings
from horde.server.stream import StreamHub
from horde.server.stream_protocol import add_stream_schemas
from horde.studies.jobs import StudyJobs
from horde.view.live import LiveView
from horde.view.manager_source import ManagerSource

DESCRIPTION = """\
Learn many predictions at once with the Horde architecture. Define worlds and runs, add demons to live
runs, step or run them, read their predictions, value maps and histories, evaluate them against
Monte-Carlo truth, and export or import snapshots. Errors: 404 unknown, 409 wrong state, 422 invalid
spec (naming the field). When HORDE_TOKEN is set, every POST, PUT, PATCH and DELETE needs
`Authorization: Bearer <token>`: the teacher's HORDE_TOKEN, or a token the teacher issued (POST /api/tokens):
a student's changes only what the student created (403 otherwise, naming the owner), a viewer's nothing.
"""


def _live_view(
    settings: Settings, manager: RunManager, port: int, access: Access, streams: StreamRuns | None = None
) -> LiveView:
    """The viser live view of the manager's runs (and the stream runs, as phase planes) on `port` (or the next
    free one), guarded by the server's tokens (the same rule as the API's) and origins."""
    return LiveView(
        ManagerSource(manager, streams),
        host=settings.host,
        port=port,
        access=access,
        allow_origin=lambda origin, host: origin_allowed(origin, host, settings.host_rule(), settings.origins),
    )


def _run_executor(settings: Settings, processes: ProcessExecutor) -> Executor:
    """Where runs, stream runs and protocol jobs learn: processes of this machine, or actors of the Ray cluster."""
    if settings.runs_on_ray():
        if settings.ray_address is None:
            raise ValueError("HORDE_RUN_WORKERS=ray needs HORDE_RAY_ADDRESS (a cluster to run on)")
        return RayExecutor(processes, settings.ray_address, settings.ray_run_cpus)
    return processes


def _lifespan(
    settings: Settings, announce: Callable[[str], None] | None
) -> Callable[[FastAPI], AbstractAsyncContextManager[None]]:
    """The app's lifespan: what it opens at start-up (into `app.state`, read by `deps`) and closes at the end."""

    @asynccontextmanager
    async def lifespan(app: FastAPI) -> AsyncIterator[None]:
        store = Store(settings.data)
        processes = ProcessExecutor(settings.worker_stall_seconds)
        processes.start()  # the fork server warms the kernels up meanwhile
        executor = _run_executor(settings, processes)
        manager = RunManager(store, settings.limits(), executor, hooks=settings.test_hooks)
        app.state.store = store
        app.state.manager = manager
        token = settings.token.get_secret_value() if settings.token is not None else None
        app.state.access = Access(store, token)
        app.state.access.forget_kind("stream")  # stream runs live in memory: none survived the last stop
        app.state.streams = StreamRuns(executor, hooks=settings.test_hooks)
        app.state.hub = StreamHub(manager, rate=settings.stream_rate)
        app.state.protocols = ProtocolJobs(store, executor, hooks=settings.test_hooks)
        app.state.studies = StudyJobs(store, processes, settings.study_executor, settings.ray_address,
                                      settings.study_workers)  # fmt: skip
        switch_interval = sys.getswitchinterval()
        sys.setswitchinterval(settings.switch_interval)
        manager.start()
        if settings.viser_port is not None:
            app.state.live_view = _live_view(
                settings, manager, settings.viser_port, app.state.access, app.state.streams
            )
            app.state.live_view.start()
            if announce is not None:
                announce(app.state.live_view.url)
        # The objects of the imports and of start-up (the live view's included) live as long as the
        # server: moved out of the collector's reach, a full collection (which holds the GIL, so stalls
        # the event loop) walks only what requests made since, instead of 170,000 objects in 130 ms.
        gc.collect()
        gc.freeze()
        try:
            yield
        finally:
            await app.state.hub.close()
            app.state.protocols.stop()
            app.state.studies.stop()
            if app.state.live_view is not None:
                app.state.live_view.stop()
                app.state.live_view = None
            manager.stop()
            app.state.streams.stop()
            executor.stop()
            processes.stop()
            store.close()
            sys.setswitchinterval(switch_interval)

    return lifespan


def create_app(settings: Settings | None = None, announce: Callable[[str], None] | None = None) -> FastAPI:
    """The Horde Lab server.

    Args:
        settings: defaults to `Settings()`, read from HORDE_* environment variables.
        announce: called with the live view's address once it listens (viser may move to the next
            free port, so the address is known only then); `horde serve` prints it.
    """
    settings = settings or Settings()
    app = FastAPI(
        title="Horde Lab",
        description=DESCRIPTION,
        version="0.1.0",
        lifespan=_lifespan(settings, announce),
        docs_url=None,
        redoc_url=None,
    )
    add_api_docs(app)
    add_stream_schemas(app)
    app.state.settings = settings
    app.state.live_view = None
    app.state.catalog = ScenarioCatalog(settings.scenarios)
    add_error_handlers(app)
    app.add_middleware(
        BodyGuard,
        max_body=settings.max_body,
        max_import_body=settings.max_import_body,
        max_demons=settings.max_demons,
    )
    app.add_middleware(HostGuard, rule=settings.host_rule())  # added last, so outermost: before the body is read
    for router in ROUTERS:
        app.include_router(router, prefix="/api")
    validate_off_loop(app)
    mount_frontend(app, settings.frontend or DIST_DIR)
    return app
