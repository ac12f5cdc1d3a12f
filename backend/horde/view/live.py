"""`LiveView`: one viser server that shows each browser the run it chose, as it happens.

Every browser (viser client) has its own view (`horde.view.viewer.Viewer`): its own scene, panel and
camera, following its own choice of run. Nothing about what is shown is shared or global: a browser's
choices change what it sees, and only the commands (play, pause, ...) change a run, for the browsers
whose token may change it (`horde.runs.access`).

A dashboard tab names itself with a random key and opens the view at `url_for(key)`, which puts
`?viewer=<key>` on the view's WebSocket address; `show(key, run, ...)` (the dashboard's
`POST /api/view`) then records that tab's choice (its run, demons, large text and the token it acts
with), which the browsers of that key, and only those, take at their next frame, now or when they
connect. A browser that opens the view without a key starts on the first run and follows its own Run
dropdown.

One thread, the view's, draws every frame and is the only one that changes the browsers' scenes and
panels: `show` and the panels' callbacks record choices and wake it. It samples the source at most `fps`
times a second, builds each viewer's scene with the pure functions of scene.py (the viewers of one frame
share the reads and the nodes: `Frame`) and applies the changes inside `client.atomic()`. A viewer
whose client has left, or whose frame fails, never stops the others or the thread. The thread only reads
snapshots, so a slow browser slows the view, never the learner.

Start and stop it explicitly (the server's lifespan does)::

    view = LiveView(source, host="127.0.0.1", port=8081)
    view.start()
    print(view.url)
    ...
    view.stop()
"""

from __future__ import annotations

import contextlib
import logging
import os
import re
import threading
import time
from collections import OrderedDict, deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any
from urllib.parse import parse_qs, quote, urlsplit

import viser

from horde.runs.access import Access
from horde.view.source import ViewSource
from horde.view.viewer import Frame, Viewer

log = logging.getLogger(__name__)

RUN_LIST_PERIOD = 1.0  # seconds between looks at the list of runs
VIEWER_KEY_PATTERN = r"^[A-Za-z0-9_-]{8,64}$"  # a dashboard tab's key (the `viewer` of POST /api/view)
VIEWER_KEY = re.compile(VIEWER_KEY_PATTERN)
MAX_KEYS = 1024  # dashboard tabs whose choice is remembered (the oldest are forgotten)
# The view thread takes at most this share of a core: after a frame that took t seconds of its CPU it rests at
# least t * (1 / MAX_DUTY - 1), so many browsers lower the frame rate instead of taking the server's time (the
# learners' and the API's: 30 browsers on one run took 108 ms a frame at first). CPU time, not wall time: on a
# busy machine a frame waits for a core, and that wait is no reason to rest longer.
MAX_DUTY = 0.3
# The view thread's OS priority: the workers' (horde.runs.forkserver.WORKER_NICENESS), below the event loop's, so
# that on a busy machine the view's frames, not the runs' steps or the API's answers, give way: a slow view shows
# fewer frames, it never slows a run.
VIEW_NICENESS = 10


@dataclass(frozen=True)
class Choice:
    """What a dashboard tab shows: a run, the demons it labels and charts (None: the view's own first ones),
    large text (None: unchanged), the token it acts with (None: none), numbered in order."""

    run: str
    demons: tuple[str, ...] | None
    large: bool | None
    secret: str | None
    version: int


class LiveView:
    """The viser live view of the runs of a `ViewSource`, one view per browser.

    Args:
        source: the runs to show.
        host: the address to bind (loopback by default).
        port: the port asked for; viser moves to the next free one, read `port` after `start`.
        fps: most frames per second.
        map_hz: value map refreshes per second while the run moves (at least 2).
        chart_hz: chart refreshes per second.
        resolution: cells per side of the value map.
        access: the server's tokens and owners: who may command which run (None: no roles, everyone may).
        allow_origin: `(origin, host) -> bool` for each browser's WebSocket upgrade; a browser refused
            is disconnected and gets no view (None: every origin).
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
        access: Access | None = None,
        allow_origin: Callable[[str | None, str | None], bool] | None = None,
    ) -> None:
        self.source = source
        self.access = access
        self.allow_origin = allow_origin
        self.host = host
        self.requested_port = port
        self.fps, self.map_hz, self.chart_hz = fps, map_hz, chart_hz
        self.resolution = resolution
        self._server: viser.ViserServer | None = None
        self._thread: threading.Thread | None = None
        self._stop = threading.Event()
        self.changed = threading.Event()  # a viewer's choice changed: draw now
        self._lock = threading.Lock()  # guards the dicts below (viser's threads, the routes' and the view's)
        self._viewers: dict[int, Viewer] = {}
        self._keys: dict[int, str | None] = {}  # client id -> its key, read from its WebSocket address
        self._choices: OrderedDict[str, Choice] = OrderedDict()  # key -> the tab's choice, newest last
        self._version = 0
        self._runs: list[tuple[str, str]] = []
        self._runs_time = -RUN_LIST_PERIOD
        self._kept: OrderedDict[tuple[object, ...], Any] = OrderedDict()  # what outlives a frame (Frame.lasting)
        self.frames = 0  # frames drawn
        self._frame_times: deque[float] = deque(maxlen=256)  # when the recent frames were drawn (frame_rate)

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

    def url_for(self, key: str) -> str:
        """The view's address for the browsers of a dashboard tab: its WebSocket address carries the key
        (the viser client connects to its `websocket` parameter)."""
        socket = f"ws://{self.host}:{self.port}/?viewer={key}"
        return f"{self.url}?websocket={quote(socket, safe='')}"

    def start(self) -> None:
        """Start the viser server and the view thread."""
        if self._server is not None:
            return
        server = viser.ViserServer(host=self.host, port=self.requested_port, verbose=False)
        self._server = server
        server.scene.world_axes.visible = False
        # Nothing in the view casts a shadow worth drawing (the world is flat and seen from above), while the
        # default lights' shadow maps cost a browser without a GPU (software WebGL) about a quarter of each frame.
        server.scene.configure_default_lights(cast_shadow=False)
        self._guard_connections(server)
        server.on_client_connect(self._add_viewer)
        server.on_client_disconnect(self._remove_viewer)
        self._stop.clear()
        self._thread = threading.Thread(target=self._loop, name="horde-live-view", daemon=True)
        self._thread.start()

    def _guard_connections(self, server: viser.ViserServer) -> None:
        """Read each browser's key from its WebSocket address, and disconnect browsers whose page came
        from another site, before any of their messages is handled (they never get a viewer).

        viser has no hook on the WebSocket handshake; its connection callbacks run (awaited) on the
        server's event loop before the connection's messages are read, and see the raw connection. The
        client is announced (`on_client_connect`) only later, after its first camera message.
        """
        allow = self.allow_origin
        infra = server._websock_server

        async def check(connection: Any) -> None:
            raw = infra._live_connections.get(connection.client_id)
            request = raw.request if raw is not None else None
            headers = request.headers if request is not None else {}
            if allow is not None and not allow(headers.get("Origin"), headers.get("Host")):
                log.warning("live view: refused a browser from origin %r", headers.get("Origin"))
                if raw is not None:
                    await raw.close(1008, "this page's origin may not open the live view")
                return
            keys = parse_qs(urlsplit(request.path).query).get("viewer", []) if request is not None else []
            with self._lock:
                self._keys[connection.client_id] = keys[0] if keys and VIEWER_KEY.match(keys[0]) else None

        infra.on_client_connect(check)

    def _add_viewer(self, client: viser.ClientHandle) -> None:
        """A browser connected (and passed the origin check): its own view. Built here, before the view thread
        knows of it; drawn by the view thread from its next frame."""
        with self._lock:
            if client.client_id not in self._keys:
                return  # refused by the origin check
            key = self._keys[client.client_id]
        try:
            viewer = Viewer.connect(client, self.source, self.changed, self.access, key, resolution=self.resolution,
                                    map_hz=self.map_hz, chart_hz=self.chart_hz)  # fmt: skip
        except Exception:  # the client left while its panel was being built
            log.debug("live view: a client left before its panel was built", exc_info=True)
            return
        with self._lock:
            if client.client_id in self._keys:  # not gone meanwhile
                self._viewers[client.client_id] = viewer
        self.changed.set()

    def _remove_viewer(self, client: viser.ClientHandle) -> None:
        with self._lock:
            viewer = self._viewers.pop(client.client_id, None)
            self._keys.pop(client.client_id, None)
        if viewer is not None:
            viewer.closed = True

    def viewers(self, key: str | None = None) -> list[Viewer]:
        """The connected browsers' views (those of one dashboard tab's key, if given)."""
        with self._lock:
            return [v for v in self._viewers.values() if key is None or v.key == key]

    def stop(self) -> None:
        """Stop the view thread and the viser server."""
        self._stop.set()
        self.changed.set()
        if self._thread is not None:
            self._thread.join(timeout=5.0)
            self._thread = None
        if self._server is not None:
            self._server.stop()
            self._server = None

    # ------------------------------------------------------------------------------------------
    # A dashboard tab's choice

    def show(
        self,
        key: str,
        run_id: str,
        demons: Sequence[str] | None = None,
        large: bool | None = None,
        secret: str | None = None,
    ) -> None:
        """Record what the dashboard tab `key` shows: this run, labelling `demons` if given, with large text
        if given, acting with the token `secret` if given. Its browsers take it at their next frame (or
        when they connect); no other browser's view changes. Touches no browser's panel or scene itself.

        Raises:
            KeyError: the source has no such run.
        """
        if run_id not in {r for r, _ in self.source.list_runs()}:
            raise KeyError(run_id)
        with self._lock:
            self._version += 1
            choice = Choice(run_id, tuple(demons) if demons is not None else None, large, secret, self._version)
            self._choices[key] = choice
            self._choices.move_to_end(key)
            while len(self._choices) > MAX_KEYS:
                self._choices.popitem(last=False)
            self._runs_time = -RUN_LIST_PERIOD  # the next frame's list of runs holds this one (it may be new)
        self.changed.set()

    def shown_run(self, key: str) -> str | None:
        """The run the dashboard tab `key` last asked its view to show (None: it has not asked)."""
        with self._lock:
            choice = self._choices.get(key)
        return choice.run if choice is not None else None

    # ------------------------------------------------------------------------------------------
    # The view thread

    def _loop(self) -> None:
        """Frames at most `fps` a second, and one at once after a choice changed; busy at most MAX_DUTY of a core
        (a frame that took long is followed by a longer rest, a choice then waiting for its end), at the
        workers' priority (VIEW_NICENESS)."""
        with contextlib.suppress(AttributeError, OSError):  # per-thread niceness is a Linux feature
            os.setpriority(os.PRIO_PROCESS, threading.get_native_id(), VIEW_NICENESS)
        period = 1.0 / self.fps
        while not self._stop.is_set():
            started, cpu = time.monotonic(), time.thread_time()
            self.refresh()
            rest = (time.thread_time() - cpu) * (1.0 / MAX_DUTY - 1.0)
            if rest > 0 and self._stop.wait(rest):
                return
            remaining = period - (time.monotonic() - started)
            if remaining > 0 and self.changed.wait(remaining):
                self.changed.clear()

    def refresh(self) -> None:
        """One frame: every viewer's run sampled (once per run and choice of demons), what changed sent."""
        now = time.monotonic()
        frame = Frame(self.source, now, self._kept)
        if now - self._runs_time >= RUN_LIST_PERIOD:
            try:
                self._runs = self.source.list_runs()
                self._runs_time = now
            except Exception:
                log.exception("live view: the list of runs failed")
        is_stream = getattr(self.source, "is_stream", None)

        def commands(run_id: str) -> bool:  # whether the run takes commands at all (a stream run takes none)
            return not (is_stream is not None and frame.memo(("is_stream", run_id), lambda: is_stream(run_id)))

        for viewer in self.viewers():
            try:
                self._take_choice(viewer)
                viewer.refresh(frame, self._runs, commands)
                viewer.last_error = ""
            except Exception as exc:  # a run that vanished, a client that left: log once per viewer, go on
                if viewer.closed:
                    continue
                if repr(exc) != viewer.last_error:
                    log.exception("live view: a frame of client %s failed", viewer.client.client_id)
                viewer.last_error = repr(exc)
        self.frames += 1
        self._frame_times.append(now)

    def frame_rate(self, window: float = 5.0) -> float:
        """Frames drawn a second over the last `window` seconds (each draws every browser's view)."""
        now = time.monotonic()
        recent = [t for t in list(self._frame_times) if now - t <= window]
        return len(recent) / window

    def _take_choice(self, viewer: Viewer) -> None:
        """The viewer's dashboard tab chose anew: the viewer takes it (run, demons, large text, token)."""
        if viewer.key is None:
            return
        with self._lock:
            choice = self._choices.get(viewer.key)
        if choice is None or choice.version == viewer.choice_version:
            return
        viewer.choice_version = choice.version
        viewer.panel.choose(choice.run, choice.demons, choice.large, choice.secret)
