"""`LiveView`: one viser server that shows a run's world, agent and predictions as they happen.

The view owns a thread that samples the source at most `fps` times a second, builds the scene with
the pure functions of scene.py and applies the changes inside `server.atomic()`. Value maps are
recomputed `map_hz` times a second while the run moves, charts `chart_hz` times a second. The
thread only reads snapshots, so a slow browser slows the view, never the learner.

Start and stop it explicitly (the server's lifespan does)::

    view = LiveView(source, host="127.0.0.1", port=8081)
    view.start()
    print(view.url)
    ...
    view.stop()
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import viser

from horde.spec import RunSpec
from horde.view import camera, scene
from horde.view.apply import SceneApplier
from horde.view.gui import ControlPanel
from horde.view.nodes import Node
from horde.view.phase_plane import phase_camera, phase_plane_nodes
from horde.view.source import ViewSnapshot, ViewSource
from horde.view.star import star_nodes

log = logging.getLogger(__name__)

RUN_LIST_PERIOD = 1.0  # seconds between looks at the list of runs


class LiveView:
    """The viser live view of the runs of a `ViewSource`.

    Args:
        source: the runs to show.
        host: the address to bind (loopback by default).
        port: the port asked for; viser moves to the next free one, read `port` after `start`.
        fps: most scene updates per second.
        map_hz: value map refreshes per second while the run moves (at least 2).
        chart_hz: chart refreshes per second.
        resolution: cells per side of the value map.
        token: when set, browsers must enter it before they may change anything (see `ControlPanel`).
        allow_origin: `(origin, host) -> bool` for each browser's WebSocket upgrade; a browser refused
            is disconnected and may change nothing (None: every origin).
    """

    def __init__(
        self,
        source: ViewSource,
        host: str = "127.0.0.1",
        port: int = 8080,
        *,
        fps: float = 30.0,
        map_hz: float = 3.0,
        chart_hz: float = 4.0,
        resolution: int = 32,
        token: str | None = None,
        allow_origin: Callable[[str | None, str | None], bool] | None = None,
    ) -> None:
        self.source = source
        self.token = token
        self.allow_origin = allow_origin
        self.host = host
        self.requested_port = port
        self.fps, self.map_hz, self.chart_hz = fps, map_hz, chart_hz
        self.resolution = resolution
        self._server: viser.ViserServer | None = None
        self._thread: threading.Thread | None = None
        self._stop = threading.Event()
        self._shown_run: str | None = None
        self._demon_names: tuple[str, ...] = ()
        self._spec: RunSpec | None = None
        self._map_key: tuple[object, ...] | None = None
        self._map_time = 0.0
        self._chart_time = 0.0
        self._runs_time = -RUN_LIST_PERIOD

    # ------------------------------------------------------------------------------------------
    # Lifecycle

    @property
    def server(self) -> viser.ViserServer:
        if self._server is None:
            raise RuntimeError("the live view is not started")
        return self._server

    @property
    def port(self) -> int:
        """The port the server listens on (after `start`)."""
        return self.server.get_port()

    @property
    def url(self) -> str:
        return f"http://{self.host}:{self.port}/"

    def start(self) -> None:
        """Start the viser server and the view thread."""
        if self._server is not None:
            return
        server = viser.ViserServer(host=self.host, port=self.requested_port, verbose=False)
        self._server = server
        server.scene.world_axes.visible = False
        self.applier = SceneApplier(server.scene)
        self.panel = ControlPanel(server, self.source, self._set_view_mode, token=self.token)
        self._guard_origins(server)
        server.on_client_disconnect(lambda client: self.panel.forget_client(client.client_id))
        self._stop.clear()
        self._thread = threading.Thread(target=self._loop, name="horde-live-view", daemon=True)
        self._thread.start()

    def _guard_origins(self, server: viser.ViserServer) -> None:
        """Disconnect browsers whose page came from another site, before any of their messages is handled.

        viser has no hook on the WebSocket handshake; its connection callbacks run (awaited) on the
        server's event loop before the connection's messages are read, and see the raw connection.
        """
        allow = self.allow_origin
        if allow is None:
            return
        infra = server._websock_server
        panel = self.panel

        async def check(connection: Any) -> None:
            raw = infra._live_connections.get(connection.client_id)
            headers = raw.request.headers if raw is not None and raw.request is not None else {}
            if not allow(headers.get("Origin"), headers.get("Host")):
                panel.rejected.add(connection.client_id)
                log.warning("live view: refused a browser from origin %r", headers.get("Origin"))
                if raw is not None:
                    await raw.close(1008, "this page's origin may not open the live view")

        infra.on_client_connect(check)

    def stop(self) -> None:
        """Stop the view thread and the viser server."""
        self._stop.set()
        self.panel_changed()
        if self._thread is not None:
            self._thread.join(timeout=5.0)
            self._thread = None
        if self._server is not None:
            self._server.stop()
            self._server = None

    def show(self, run_id: str, demons: Sequence[str] | None = None) -> None:
        """Switch the view (every connected browser) to this run, labelling `demons` if given.

        Raises:
            KeyError: the source has no such run.
        """
        runs = self.source.list_runs()
        if run_id not in {r for r, _ in runs}:
            raise KeyError(run_id)
        self.panel.set_runs(runs)
        self.panel.select_run(run_id)
        if demons is not None:
            self.panel.show_demons(demons)

    @property
    def shown_run(self) -> str | None:
        return self.panel.run_id if self._server is not None else None

    def panel_changed(self) -> None:
        if self._server is not None:
            self.panel.changed.set()

    # ------------------------------------------------------------------------------------------
    # The view thread

    def _loop(self) -> None:
        """Frames at most `fps` a second, and one at once after a GUI change."""
        period = 1.0 / self.fps
        last_error = ""
        while not self._stop.is_set():
            started = time.monotonic()
            try:
                self.refresh()
                last_error = ""
            except Exception as exc:  # a run that vanished, a client that left: log once, go on
                if repr(exc) != last_error:
                    log.exception("live view refresh failed")
                last_error = repr(exc)
            remaining = period - (time.monotonic() - started)
            if remaining > 0 and self.panel.changed.wait(remaining):
                self.panel.changed.clear()

    def refresh(self) -> None:
        """One frame: sample the chosen run and send what changed."""
        now = time.monotonic()
        panel = self.panel
        if now - self._runs_time >= RUN_LIST_PERIOD:
            self._runs_time = now
            panel.set_runs(self.source.list_runs())
        run_id = panel.run_id
        if run_id is None:
            self._show_nothing()
            return
        is_phase = getattr(self.source, "is_phase", None)
        if is_phase is not None and is_phase(run_id):
            self._refresh_phase(run_id, now)
            return
        snapshot = self.source.snapshot(run_id, panel.shown)
        names = tuple(demon.name for demon in snapshot.spec.demons)
        if run_id != self._shown_run or names != self._demon_names:
            self._switch_run(snapshot, names)
            snapshot = self.source.snapshot(run_id, panel.shown)
        with self.server.atomic():
            self.applier.apply(scene.world_nodes(snapshot.spec.grid, snapshot.indicator_colors), "world")
            self.applier.apply(scene.agent_nodes(snapshot, panel.shown), "agent")
            self._refresh_map(snapshot, now)
        panel.show_state(snapshot)
        if now - self._chart_time >= 1.0 / self.chart_hz:
            self._chart_time = now
            panel.show_charts(snapshot, panel.shown)

    def _show_nothing(self) -> None:
        if self._shown_run is not None:
            self.applier.clear()
            self._shown_run, self._demon_names = None, ()

    def _switch_run(self, snapshot: ViewSnapshot, names: tuple[str, ...]) -> None:
        """A newly chosen run, or demons that joined or left the run shown: new demon widgets."""
        if snapshot.run_id != self._shown_run:
            self.applier.clear()
        self._shown_run, self._demon_names, self._map_key = snapshot.run_id, names, None
        self.panel.set_demons(names)
        if self._spec is None or self._spec.world != snapshot.spec.world:
            self._spec = snapshot.spec
            self._set_view_mode(self.panel.three_d)
        self._spec = snapshot.spec

    def _refresh_map(self, snapshot: ViewSnapshot, now: float) -> None:
        demon = self.panel.value_demon
        if demon is None:
            self.applier.apply([], "value_map")
            return
        key = (snapshot.run_id, demon, self.panel.three_d, snapshot.total_steps, snapshot.episode)
        if key == self._map_key:
            return
        selection_changed = self._map_key is None or key[:3] != self._map_key[:3]
        if not selection_changed and now - self._map_time < 1.0 / self.map_hz:
            return
        world = snapshot.spec.grid
        values = self.source.value_map(snapshot.run_id, demon, self.resolution)
        greedy = self.source.greedy_actions(snapshot.run_id, demon, scene.arrow_resolution(world))
        self.applier.apply(
            scene.value_map_nodes(world, demon, np.asarray(values), greedy, self.panel.three_d), "value_map"
        )
        self._map_key, self._map_time = key, now

    # ------------------------------------------------------------------------------------------
    # Runs without a plane (Gymnasium and stream runs): a phase plane of two sensors

    def _refresh_phase(self, run_id: str, now: float) -> None:
        """The phase plane of the chosen demon over the chosen sensors, redrawn `map_hz` times a second
        while records arrive, at once when the choice changes."""
        panel = self.panel
        sensors, demons, received, learned = self.source.phase_status(run_id)  # type: ignore[attr-defined]
        is_stream = getattr(self.source, "is_stream", lambda run: True)(run_id)
        if run_id != self._shown_run or demons != self._demon_names:
            if run_id != self._shown_run:
                self.applier.clear()
            self._shown_run, self._demon_names, self._map_key, self._spec = run_id, demons, None, None
            panel.set_demons(demons, with_shown=not is_stream)
            if self._picture(run_id, None) is None:  # the star and the chains have no axes
                panel.set_sensors(sensors)
            self._point_camera(phase_camera())
        if is_stream:
            panel.show_phase_state(received, learned)
        else:  # a live run of a Gymnasium world: its status, counters and charts as a grid run's
            snapshot = self.source.snapshot(run_id, panel.shown)
            panel.show_state(snapshot)
            if now - self._chart_time >= 1.0 / self.chart_hz:
                self._chart_time = now
                panel.show_charts(snapshot, panel.shown)
        key = (run_id, panel.value_demon, panel.phase_x, panel.phase_y, received)
        if key == self._map_key:
            return
        if self._map_key is not None and key[:4] == self._map_key[:4] and now - self._map_time < 1.0 / self.map_hz:
            return
        picture = self._picture(run_id, panel.value_demon)
        if picture is not None:  # Baird's star or a chain: its states, the agent's, in place of a phase plane
            with self.server.atomic():
                self.applier.apply(picture, "phase")
            self._map_key, self._map_time = key, now
            return
        phase = self.source.phase_snapshot(run_id, panel.value_demon, panel.phase_x, panel.phase_y,  # type: ignore[attr-defined]
                                           self.resolution)  # fmt: skip
        with self.server.atomic():
            self.applier.apply(phase_plane_nodes(phase.x, phase.y, phase.demon, phase.values, phase.trail), "phase")
        self._map_key, self._map_time = key, now

    def _picture(self, run_id: str, demon: str | None) -> list[Node] | None:
        """The nodes of a world drawn state by state (Baird's star, a chain: `star_nodes`, `ChainPicture`), or
        None for a world drawn as a phase plane."""
        star = getattr(self.source, "star", lambda run, demon: None)(run_id, demon)
        if star is not None:
            return star_nodes(*star)
        chain = getattr(self.source, "chain", lambda run, demon: None)(run_id, demon)
        return None if chain is None else chain.nodes()

    # ------------------------------------------------------------------------------------------
    # Camera

    def _set_view_mode(self, three_d: bool) -> None:
        """Point the initial camera and every connected client's camera at the world."""
        if self._spec is None:
            return
        world = self._spec.grid
        self._point_camera(camera.tilted(world) if three_d else camera.top_down(world))

    def _point_camera(self, pose: camera.CameraPose) -> None:
        initial = self.server.initial_camera
        initial.fov = pose.fov
        initial.position = pose.position
        initial.look_at = pose.look_at
        initial.up = pose.up
        for client in self.server.get_clients().values():
            with client.atomic():
                client.camera.fov = pose.fov
                client.camera.up_direction = pose.up
                client.camera.position = pose.position
                client.camera.look_at = pose.look_at
        self.panel_changed()
