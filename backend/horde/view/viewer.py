"""`Viewer`: what one browser (one viser client) of the live view sees: its run, scene, panel and camera.

Each viser client gets a `Viewer` when it connects. It draws into the client's own scene
(`client.scene`), builds its panel in the client's own GUI (`client.gui`) and points the client's own
camera, so a browser's choices (which run, which demons, 3-D) change what that browser sees and
nothing else. `FrameReads` lets the viewers of one frame share the source's reads: thirty browsers on
one run cost one snapshot a frame, not thirty.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

import numpy as np
import viser

from horde.spec import RunSpec
from horde.view import camera, scene
from horde.view.apply import SceneApplier
from horde.view.gui import ControlPanel
from horde.view.phase_plane import phase_camera, phase_plane_nodes
from horde.view.source import ViewSnapshot, ViewSource
from horde.view.star import star_nodes


class FrameReads:
    """The source's reads (snapshots, value maps, phase planes) of one frame, each made once.

    Calls with the same arguments return the first call's answer; a call that raises is not kept.
    Commands do not go through here: the panels send them to the source itself.
    """

    def __init__(self, source: ViewSource) -> None:
        self.source = source
        self._answers: dict[tuple[object, ...], object] = {}

    def __getattr__(self, name: str) -> Callable[..., Any]:
        method = getattr(self.source, name)  # AttributeError for reads the source does not offer

        def read(*args: object) -> object:
            key = (name, *args)
            if key not in self._answers:
                self._answers[key] = method(*args)
            return self._answers[key]

        return read


class Viewer:
    """One browser's live view.

    Args:
        client: the viser client.
        source: the runs (commands go here).
        changed: set when this viewer's choices change (the view thread redraws at once).
        token: the server's token (see `ControlPanel`).
        resolution: cells per side of the value map.
        map_hz: value map refreshes per second while the run moves.
        chart_hz: chart refreshes per second.
        key: the dashboard tab this browser belongs to (the `viewer` of `?viewer=` on its WebSocket
            address), or None for a browser that opened the view on its own.
    """

    def __init__(
        self,
        client: viser.ClientHandle,
        source: ViewSource,
        changed: threading.Event,
        *,
        token: str | None,
        resolution: int,
        map_hz: float,
        chart_hz: float,
        key: str | None,
    ) -> None:
        self.client = client
        self.key = key
        self.resolution, self.map_hz, self.chart_hz = resolution, map_hz, chart_hz
        self.applier = SceneApplier(client.scene)
        self.panel = ControlPanel(client, source, self._set_view_mode, changed, token=token)
        self._shown_run: str | None = None
        self._demon_names: tuple[str, ...] = ()
        self._spec: RunSpec | None = None
        self._map_key: tuple[object, ...] | None = None
        self._map_time = 0.0
        self._chart_time = 0.0
        self.last_error = ""  # the last frame's failure (logged once, not every frame)

    def refresh(self, reads: Any, now: float) -> None:
        """One frame: sample the chosen run (through this frame's `FrameReads`) and send what changed."""
        panel = self.panel
        run_id = panel.run_id
        if run_id is None:
            self._show_nothing()
            return
        if reads.is_phase(run_id):
            self._refresh_phase(reads, run_id, now)
            return
        shown = tuple(panel.shown)
        snapshot = reads.snapshot(run_id, shown)
        names = tuple(demon.name for demon in snapshot.spec.demons)
        if run_id != self._shown_run or names != self._demon_names:
            self._switch_run(snapshot, names)
            shown = tuple(panel.shown)
            snapshot = reads.snapshot(run_id, shown)
        with self.client.atomic():
            self.applier.apply(scene.world_nodes(snapshot.spec.grid, snapshot.indicator_colors), "world")
            self.applier.apply(scene.agent_nodes(snapshot, shown), "agent")
            self._refresh_map(reads, snapshot, now)
        panel.show_state(snapshot)
        if now - self._chart_time >= 1.0 / self.chart_hz:
            self._chart_time = now
            panel.show_charts(snapshot, shown)

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

    def _refresh_map(self, reads: Any, snapshot: ViewSnapshot, now: float) -> None:
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
        values = reads.value_map(snapshot.run_id, demon, self.resolution)
        greedy = reads.greedy_actions(snapshot.run_id, demon, scene.arrow_resolution(world))
        self.applier.apply(
            scene.value_map_nodes(world, demon, np.asarray(values), greedy, self.panel.three_d), "value_map"
        )
        self._map_key, self._map_time = key, now

    # ------------------------------------------------------------------------------------------
    # Runs without a plane (Gymnasium and stream runs): a phase plane of two sensors

    def _refresh_phase(self, reads: Any, run_id: str, now: float) -> None:
        """The phase plane of the chosen demon over the chosen sensors, redrawn `map_hz` times a second
        while records arrive, at once when the choice changes."""
        panel = self.panel
        sensors, demons, received, learned = reads.phase_status(run_id)
        is_stream = reads.is_stream(run_id)
        if run_id != self._shown_run or demons != self._demon_names:
            if run_id != self._shown_run:
                self.applier.clear()
            self._shown_run, self._demon_names, self._map_key, self._spec = run_id, demons, None, None
            panel.set_demons(demons, with_shown=not is_stream)
            if reads.star(run_id, None) is None:  # the star has no axes
                panel.set_sensors(sensors)
            self._point_camera(phase_camera())
        if is_stream:
            panel.show_phase_state(received, learned)
        else:  # a live run of a Gymnasium world: its status, counters and charts as a grid run's
            shown = tuple(panel.shown)
            snapshot = reads.snapshot(run_id, shown)
            panel.show_state(snapshot)
            if now - self._chart_time >= 1.0 / self.chart_hz:
                self._chart_time = now
                panel.show_charts(snapshot, shown)
        key = (run_id, panel.value_demon, panel.phase_x, panel.phase_y, received)
        if key == self._map_key:
            return
        if self._map_key is not None and key[:4] == self._map_key[:4] and now - self._map_time < 1.0 / self.map_hz:
            return
        star = reads.star(run_id, panel.value_demon)
        if star is not None:  # Baird's star: its seven states and the agent's, in place of a phase plane
            with self.client.atomic():
                self.applier.apply(star_nodes(*star), "phase")
            self._map_key, self._map_time = key, now
            return
        phase = reads.phase_snapshot(run_id, panel.value_demon, panel.phase_x, panel.phase_y, self.resolution)
        with self.client.atomic():
            self.applier.apply(phase_plane_nodes(phase.x, phase.y, phase.demon, phase.values, phase.trail), "phase")
        self._map_key, self._map_time = key, now

    # ------------------------------------------------------------------------------------------
    # Camera

    def _set_view_mode(self, three_d: bool) -> None:
        """Point this browser's camera at the world, from above or tilted."""
        if self._spec is None:
            return
        world = self._spec.grid
        self._point_camera(camera.tilted(world) if three_d else camera.top_down(world))

    def _point_camera(self, pose: camera.CameraPose) -> None:
        client = self.client
        with client.atomic():
            client.camera.fov = pose.fov
            client.camera.up_direction = pose.up
            client.camera.position = pose.position
            client.camera.look_at = pose.look_at
        self.panel.changed.set()
