"""`Viewer`: what one browser (one viser client) of the live view sees: its run, scene, panel and camera.

Each viser client gets a `Viewer` when it connects. It draws into the client's own scene
(`client.scene`), builds its panel in the client's own GUI (`client.gui`) and points the client's own
camera, so a browser's choices (which run, which demons, 3-D, large text) change what that browser sees
and nothing else. Only the view thread calls `refresh`; see `horde.view.gui` for the callbacks.

`Frame` lets the viewers of one frame share the source's reads and the scene's nodes: thirty browsers
on one run cost one snapshot and one build of its nodes a frame, not thirty.
"""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Callable, Sequence
from functools import partial
from typing import Any, TypeVar

import numpy as np
import viser

from horde.runs.access import Access
from horde.spec import RunSpec
from horde.view import camera, scene
from horde.view.apply import SceneApplier
from horde.view.gui import LARGE_SCALE, ControlPanel
from horde.view.nodes import Node
from horde.view.phase_plane import phase_camera, phase_plane_nodes
from horde.view.source import ViewSnapshot, ViewSource
from horde.view.star import star_nodes

T = TypeVar("T")
Kept = OrderedDict[tuple[object, ...], Any]
SLOW_HZ = 5.0  # redraws a second of the trail (the largest message) and of the predictions' label (numbers that
# change every frame at full speed are not read faster); the agent itself moves every frame
SLOW_NODES = ("/trail", "/predictions")


class Frame:
    """The source's reads (snapshots, value maps, phase planes) and the scene's nodes of one frame, each made once.

    `read(name, *args)` calls the source's method; `memo(key, make)` keeps anything else. A call with the same
    arguments returns the first call's answer; a call that raises is not kept. `lasting(key, make)` keeps what
    outlives a frame (a run's world nodes: the same objects frame after frame, which the appliers then skip
    without comparing them field by field) in `kept`, the view's, at most KEPT of them; `recent(key, state,
    max_age, make)` keeps what is remade as a run moves, but at most once per `max_age` seconds for all the
    viewers (a run's value map: one read of its worker and one PNG however many browsers show it, and the
    same nodes for each). Commands do not go through here: the panels send them to the source itself.
    """

    KEPT = 64

    def __init__(self, source: ViewSource, now: float, kept: Kept | None = None) -> None:
        self.source = source
        self.now = now
        self._answers: dict[tuple[object, ...], object] = {}
        self._kept: Kept = OrderedDict() if kept is None else kept

    def memo(self, key: tuple[object, ...], make: Callable[[], T]) -> T:
        if key not in self._answers:
            self._answers[key] = make()
        return self._answers[key]  # type: ignore[return-value]

    def lasting(self, key: tuple[object, ...], make: Callable[[], T]) -> T:
        if key not in self._kept:
            self._kept[key] = make()
            while len(self._kept) > self.KEPT:
                self._kept.popitem(last=False)
        return self._kept[key]

    def recent(self, key: tuple[object, ...], state: object, max_age: float, make: Callable[[], T]) -> T:
        """What `make` made for `key` in this frame or an earlier one, while `state` (say, the run's step) has not
        changed or for `max_age` seconds after it was made; made anew (and kept) otherwise."""
        slot = ("recent", *key)
        kept = self._kept.get(slot)
        if kept is not None and (kept[1] == state or self.now - kept[0] < max_age):
            return kept[2]
        value = make()
        self._kept[slot] = (self.now, state, value)
        self._kept.move_to_end(slot)
        while len(self._kept) > self.KEPT:
            self._kept.popitem(last=False)
        return value

    def read(self, name: str, *args: object) -> Any:
        method = getattr(self.source, name)  # AttributeError for reads the source does not offer
        return self.memo(("read", name, *args), lambda: method(*args))

    def has(self, name: str) -> bool:
        return hasattr(self.source, name)


def _picture(frame: Frame, run_id: str, demon: str | None) -> list[Node] | None:
    """The nodes of a world drawn state by state: Baird's star (`star_nodes`), a chain (`view.chain`); None for a
    world drawn as a phase plane."""
    star = frame.read("star", run_id, demon) if frame.has("star") else None
    if star is not None:
        return star_nodes(*star)
    chain = frame.read("chain", run_id, demon) if frame.has("chain") else None
    return None if chain is None else chain.nodes()


class Viewer:
    """One browser's live view.

    Args:
        client: the viser client.
        source: the runs (commands go here).
        panel: the client's panel (`ControlPanel`).
        key: the dashboard tab this browser belongs to (the `viewer` of `?viewer=` on its WebSocket
            address), or None for a browser that opened the view on its own.
        resolution: cells per side of the value map.
        map_hz: value map refreshes per second while the run moves.
        chart_hz: chart refreshes per second.
    """

    def __init__(
        self,
        client: viser.ClientHandle,
        panel: ControlPanel,
        key: str | None,
        *,
        resolution: int,
        map_hz: float,
        chart_hz: float,
    ) -> None:
        self.client = client
        self.panel = panel
        self.key = key
        self.resolution, self.map_hz, self.chart_hz = resolution, map_hz, chart_hz
        self.applier = SceneApplier(client.scene)
        self.closed = False  # the client left (set by the view's disconnect callback)
        self.choice_version = -1  # the dashboard's last choice taken (LiveView.show)
        self.last_error = ""  # the last frame's failure (logged once, not every frame)
        self._shown_run: str | None = None
        self._demon_names: tuple[str, ...] = ()
        self._spec: RunSpec | None = None
        self._chart_time = 0.0
        self._slow_time = 0.0

    @classmethod
    def connect(
        cls, client: viser.ClientHandle, source: ViewSource, changed: Any, access: Access | None, key: str | None,
        *, resolution: int, map_hz: float, chart_hz: float,
    ) -> Viewer:  # fmt: skip
        """A viewer with a new panel in the client's own GUI."""
        panel = ControlPanel(client, source, changed, access)
        return cls(client, panel, key, resolution=resolution, map_hz=map_hz, chart_hz=chart_hz)

    # ------------------------------------------------------------------------------------------
    # A frame

    def refresh(self, frame: Frame, runs: Sequence[tuple[str, str]], commands: Callable[[str], bool]) -> None:
        """One frame: the panel follows the browser's choices, the chosen run is sampled (through this frame's
        `frame`) and what changed is sent, as one message to the browser (`client.atomic`: its scene and panel
        change together, and viser's event loop is woken once per browser and frame, not once per change).
        `commands(run)` says whether the run takes commands at all."""
        with self.client.atomic():
            self._refresh(frame, runs, commands)

    def _refresh(self, frame: Frame, runs: Sequence[tuple[str, str]], commands: Callable[[str], bool]) -> None:
        panel = self.panel
        panel.set_runs(runs)
        run_id = panel.run_id
        panel.commands.sync(run_id, run_id is not None and commands(run_id))
        three_d_changed, large_changed = panel.sync_looks()
        if large_changed:  # labels are redrawn at their new size
            self.applier.label_scale = LARGE_SCALE if panel.large else 1.0
            self.applier.clear()
        if run_id is None:
            self._show_nothing()
            return
        if three_d_changed:
            self._set_view_mode(panel.three_d)
        if frame.has("is_phase") and frame.read("is_phase", run_id):
            self._refresh_phase(frame, run_id)
            return
        shown = tuple(panel.shown)
        snapshot: ViewSnapshot = frame.read("snapshot", run_id, shown)
        names = tuple(demon.name for demon in snapshot.spec.demons)
        if run_id != self._shown_run or names != self._demon_names:
            self._switch_run(snapshot, names)
            shown = tuple(panel.shown)
            snapshot = frame.read("snapshot", run_id, shown)
        panel.sync_demons()
        now = frame.now
        world_spec = snapshot.spec.grid
        # Keyed by the spec's identity (specs hold lists: no hash); the kept entry holds the spec, so its id is
        # not reused while the entry lives.
        colours = snapshot.indicator_colors
        _, world = frame.lasting(("world", run_id, id(world_spec), tuple(colours.items())),
                                 lambda: (world_spec, scene.world_nodes(world_spec, colours)))  # fmt: skip
        agent = frame.memo(("agent", run_id, shown), lambda: scene.agent_nodes(snapshot, shown))
        drawn = self.applier.drawn
        if now - self._slow_time >= 1.0 / SLOW_HZ or any(n.name not in drawn for n in agent if n.name in SLOW_NODES):
            self._slow_time = now
        else:  # the trail and label drawn stay until their next redraw; the agent moves now
            agent = [n for n in agent if n.name not in SLOW_NODES] + [drawn[n][0] for n in SLOW_NODES if n in drawn]
        self.applier.apply(world, "world")
        self.applier.apply(agent, "agent")
        self._refresh_map(frame, snapshot)
        panel.show_state(snapshot)
        if now - self._chart_time >= 1.0 / self.chart_hz:
            self._chart_time = now
            panel.show_charts(snapshot, shown)

    def _show_nothing(self) -> None:
        if self._shown_run is not None:
            self.applier.clear()
            self._shown_run, self._demon_names = None, ()
            self.panel.set_demons(())

    def _switch_run(self, snapshot: ViewSnapshot, names: tuple[str, ...]) -> None:
        """A newly chosen run, or demons that joined or left the run shown: new demon widgets."""
        if snapshot.run_id != self._shown_run:
            self.applier.clear()
        self._shown_run, self._demon_names = snapshot.run_id, names
        self.panel.set_demons(names)
        if self._spec is None or self._spec.world != snapshot.spec.world:
            self._spec = snapshot.spec
            self._set_view_mode(self.panel.three_d)
        self._spec = snapshot.spec

    def _refresh_map(self, frame: Frame, snapshot: ViewSnapshot) -> None:
        """The value map of the demon chosen, remade `map_hz` times a second while the run moves: once for every
        browser that shows the same map (`Frame.recent`), so thirty browsers of a run ask its worker for one map,
        not thirty, and the applier finds the same nodes it drew (sending nothing) until the next one."""
        demon = self.panel.value_demon
        if demon is None:
            self.applier.apply([], "value_map")
            return
        world, three_d = snapshot.spec.grid, self.panel.three_d

        def build() -> list[Node]:
            values = frame.read("value_map", snapshot.run_id, demon, self.resolution)
            greedy = frame.read("greedy_actions", snapshot.run_id, demon, scene.arrow_resolution(world))
            return scene.value_map_nodes(world, demon, np.asarray(values), greedy, three_d)

        key = ("value_map", snapshot.run_id, demon, three_d, self.resolution)
        nodes = frame.recent(key, (snapshot.total_steps, snapshot.episode), 1.0 / self.map_hz, build)
        self.applier.apply(nodes, "value_map")

    # ------------------------------------------------------------------------------------------
    # Runs without a plane (Gymnasium and stream runs): a phase plane of two sensors

    def _refresh_phase(self, frame: Frame, run_id: str) -> None:
        """The phase plane of the chosen demon over the chosen sensors, redrawn `map_hz` times a second
        while records arrive, at once when the choice changes."""
        panel = self.panel
        sensors, demons, received, learned = frame.read("phase_status", run_id)
        is_stream = frame.read("is_stream", run_id) if frame.has("is_stream") else True
        star_of = partial(_picture, frame, run_id)  # Baird's star or a chain: drawn state by state
        if run_id != self._shown_run or demons != self._demon_names:
            if run_id != self._shown_run:
                self.applier.clear()
            self._shown_run, self._demon_names, self._spec = run_id, demons, None
            panel.set_demons(demons, with_shown=not is_stream)
            if star_of(None) is None:  # the star and the chains have no axes
                panel.set_sensors(sensors)
            self._point_camera(phase_camera())
        panel.sync_demons()
        now = frame.now
        if is_stream:
            panel.show_phase_state(received, learned)
        else:  # a live run of a Gymnasium world: its status, counters and charts as a grid run's
            shown = tuple(panel.shown)
            snapshot = frame.read("snapshot", run_id, shown)
            panel.show_state(snapshot)
            if now - self._chart_time >= 1.0 / self.chart_hz:
                self._chart_time = now
                panel.show_charts(snapshot, shown)
        demon, x, y = panel.value_demon, panel.phase_x, panel.phase_y

        def build() -> list[Node]:
            picture = star_of(demon)
            if picture is not None:  # Baird's star or a chain: its states and the agent's, in place of a phase plane
                return picture
            phase = frame.read("phase_snapshot", run_id, demon, x, y, self.resolution)
            return phase_plane_nodes(phase.x, phase.y, phase.demon, phase.values, phase.trail)

        # Remade map_hz times a second while records arrive, once for every browser that shows it (Frame.recent).
        key = ("phase", run_id, demon, x, y, self.resolution)
        self.applier.apply(frame.recent(key, received, 1.0 / self.map_hz, build), "phase")

    # ------------------------------------------------------------------------------------------
    # Camera

    def _set_view_mode(self, three_d: bool) -> None:
        """Point this browser's camera at the world, from above or tilted."""
        if self._spec is None or self._spec.world.kind != "grid":
            return
        world = self._spec.grid
        self._point_camera(camera.tilted(world) if three_d else camera.top_down(world))

    def _point_camera(self, pose: camera.CameraPose) -> None:
        camera = self.client.camera
        camera.fov = pose.fov
        camera.up_direction = pose.up
        camera.position = pose.position
        camera.look_at = pose.look_at
