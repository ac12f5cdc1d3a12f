"""`ControlPanel`: the viser GUI of the live view (run and demon selectors, commands, readouts, charts).

The panel is shared by every browser that shows the view (a classroom watches one teacher's
choices). GUI callbacks run on viser's thread pool: they forward commands to the source and record
the selection, which the view thread reads at its next frame.

With a token (the server's HORDE_TOKEN) the shared panel changes nothing: it has no commands (play,
pause, step, reset, speed), and a change of its selectors (run, value map, demons shown, 3-D) from a
browser that has not entered the token is undone and answered with a notification. Each browser gets
its own "Token" field; once it holds the token, that browser alone gets the commands, in its own
folder, and may change the selectors. Browsers whose page came from another site (see
`horde.server.origins`) are disconnected and may change nothing, with or without a token.
"""

from __future__ import annotations

import hmac
import threading
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import viser
import viser.uplot

from horde.view.palette import demon_colour
from horde.view.source import CommandRefusedError, ViewSnapshot, ViewSource

MAX_DEMON_CHECKBOXES = 12  # demons that can be ticked for labels and charts (the first ones)
MAX_SHOWN = 12  # demons labelled and charted at once (the dashboard may choose them among thousands)
DEFAULT_SHOWN = 3  # demons ticked when a run is chosen
SPEED_RANGE = (1, 200)  # steps per second the speed slider offers (a faster run is shown at its end)


def _series(names: Sequence[str], order: Sequence[str]) -> tuple[viser.uplot.Series, ...]:
    """uPlot series: the step axis, then one line per demon in its colour (by its place in `order`)."""
    series: list[viser.uplot.Series] = [{"label": "step"}]
    for name in names:
        series.append({"label": name, "stroke": demon_colour(order.index(name)), "width": 2})
    return tuple(series)


def _tell(event: Any, title: str, body: str) -> None:
    """A red notification to the one client behind a GUI event (none for an event without a client)."""
    client = getattr(event, "client", None)
    if client is not None:
        client.add_notification(title, body, color="red")


def _set(handle: Any, value: object) -> None:
    """Assign a GUI input's value (sent only if it changed); viser's property confuses mypy."""
    handle.value = value


class ControlPanel:
    """The GUI of one viser server.

    Args:
        server: the viser server.
        source: where commands go.
        on_view_mode: called with True (tilted 3-D view) or False (top-down) when the user switches.
    """

    def __init__(
        self,
        server: viser.ViserServer,
        source: ViewSource,
        on_view_mode: Callable[[bool], None],
        token: str | None = None,
    ) -> None:
        self.server = server
        self.source = source
        self.on_view_mode = on_view_mode
        self.token = token
        self.unlocked: set[int] = set()  # clients that entered the token
        self.rejected: set[int] = set()  # clients whose page came from another site
        self._speed_inputs: dict[int | None, tuple[Any, Any]] = {}  # owner (None: shared) -> (slider, checkbox)
        self.lock = threading.Lock()
        self.run_id: str | None = None
        self.value_demon: str | None = None
        self.shown: tuple[str, ...] = ()
        self.three_d = False
        self.phase_x: str | None = None  # the sensors along a phase plane's axes (stream runs)
        self.phase_y: str | None = None
        self.changed = threading.Event()  # the selection changed: redraw now
        self._run_ids: dict[str, str] = {}  # dropdown option -> run id
        self._demon_handles: list[viser.GuiDropdownHandle[str] | viser.GuiFolderHandle] = []
        self._checkboxes: dict[str, viser.GuiCheckboxHandle] = {}
        self._ticking = False
        self._charts: tuple[viser.GuiUplotHandle, viser.GuiUplotHandle] | None = None
        self._chart_names: tuple[str, ...] = ()
        self._build()

    # ------------------------------------------------------------------------------------------
    # Fixed widgets

    def _build(self) -> None:
        gui = self.server.gui
        gui.configure_theme(control_width="large")
        self._syncing = False  # True while the view itself sets widget values
        # Minimized to a bar at first: embedded in the dashboard the panel would cover half the world, and
        # the dashboard has the same controls; one click on the bar opens it.
        gui.main_panel.minimize()
        self.run = gui.add_dropdown("Run", ("(none)",), order=0)
        self.run.on_update(self._on_run)
        self.status = gui.add_text("Status", "", disabled=True, order=1)
        if self.token is None:
            self._add_commands(gui, None)
        self.episode = gui.add_number("Episode", 0, disabled=True, order=9)
        self.step = gui.add_number("Step", 0, disabled=True, order=10)
        self.total = gui.add_number("Total steps", 0, disabled=True, order=11)
        self.episode_return = gui.add_number("Return", 0.0, step=0.001, disabled=True, order=12)
        self.view_button = gui.add_button("Tilt to 3-D", order=13)
        self.view_button.on_click(lambda event: self._toggle_view() if self._may_change(event) else None)
        if self.token is not None:
            self.server.on_client_connect(self._offer_token)

    def _add_commands(self, gui: Any, owner: int | None) -> None:
        """Play, pause, step, reset and speed, on the shared panel or on one unlocked client's own."""
        play, pause = gui.add_button("Play", order=2), gui.add_button("Pause", order=3)
        play.on_click(lambda event: self._command(event, self.source.play))
        pause.on_click(lambda event: self._command(event, self.source.pause))
        steps = gui.add_number("Steps per click", 1, min=1, max=10_000, step=1, order=4)
        step = gui.add_button("Step", order=5)
        step.on_click(lambda event: self._command(event, lambda run: self.source.step(run, int(steps.value))))
        reset = gui.add_button("Reset", order=6)
        reset.on_click(lambda event: self._command(event, self.source.reset))
        hz = gui.add_slider("Speed (steps/s)", *SPEED_RANGE, 1, 10, order=7)
        full_speed = gui.add_checkbox("Full speed", False, hint="as fast as possible", order=8)
        hz.on_update(lambda event: self._set_hz(event, hz, full_speed))
        full_speed.on_update(lambda event: self._set_hz(event, hz, full_speed))
        self._speed_inputs[owner] = (hz, full_speed)

    # ------------------------------------------------------------------------------------------
    # Who may change what

    def _may_change(self, event: Any) -> bool:
        """Whether the client behind a GUI event may change runs and the shared view; tells it if not."""
        client_id = getattr(event, "client_id", None)
        if client_id in self.rejected:
            return False
        if self.token is None or client_id in self.unlocked:
            return True
        _tell(event, "Read-only", "This server needs its token to change anything: enter it under Token.")
        return False

    def _offer_token(self, client: viser.ClientHandle) -> None:
        """A "Token" field of this client's own; the right token gives it the commands."""
        field = client.gui.add_text("Token", "", hint="the server's HORDE_TOKEN: unlocks the commands", order=-1)

        def check(_: object) -> None:
            assert self.token is not None
            if client.client_id in self.rejected or not field.value:
                return
            if not hmac.compare_digest(field.value.encode(), self.token.encode()):
                client.add_notification("Wrong token", "That is not this server's token.", color="red")
                return
            self.unlocked.add(client.client_id)
            field.remove()
            with client.gui.add_folder("Commands", order=1.5):
                self._add_commands(client.gui, client.client_id)
            client.add_notification("Unlocked", "This browser may now change runs.", color="green")

        field.on_update(check)

    def forget_client(self, client_id: int) -> None:
        """A client left: drop what the panel knew of it."""
        self.unlocked.discard(client_id)
        self.rejected.discard(client_id)
        self._speed_inputs.pop(client_id, None)

    def _command(self, event: Any, command: Callable[[str], None]) -> None:
        """Forward a command; a refusal (or a run gone meanwhile) is told to the client who clicked, as a
        notification (viser's way of answering one browser), the others seeing nothing."""
        if self.run_id is None or not self._may_change(event):
            return
        try:
            command(self.run_id)
        except CommandRefusedError as exc:
            _tell(event, "Not done", str(exc))
        except KeyError:
            _tell(event, "Run gone", "This run no longer exists; choose another under Run.")
        self.changed.set()

    def _set_hz(self, event: Any, hz: Any, full_speed: Any) -> None:
        if self._syncing:
            return
        self._command(event, lambda run: self.source.set_hz(run, None if full_speed.value else float(hz.value)))

    def _on_run(self, event: Any) -> None:
        if self._may_change(event):
            self._select_run(self._run_ids.get(self.run.value))
            return
        option = next((o for o, r in self._run_ids.items() if r == self.run_id), None)  # undo it
        if option is not None:
            _set(self.run, option)

    def _toggle_view(self) -> None:
        self.three_d = not self.three_d
        self.view_button.label = "Top-down 2-D" if self.three_d else "Tilt to 3-D"
        self.on_view_mode(self.three_d)
        self.changed.set()

    # ------------------------------------------------------------------------------------------
    # Runs and demons

    def set_runs(self, runs: Sequence[tuple[str, str]]) -> None:
        """Offer these runs; the first one is chosen when none is."""
        options = {(run_id if label in ("", run_id) else f"{label} [{run_id}]"): run_id for run_id, label in runs}
        if options == self._run_ids:
            return
        self._run_ids = options
        self.run.options = tuple(options) or ("(none)",)
        current = next((o for o, r in options.items() if r == self.run_id), None)
        if current is None:
            self._select_run(next(iter(options.values()), None))
        else:
            _set(self.run, current)

    def select_run(self, run_id: str) -> None:
        """Show this run (the dashboard asks for the run it has selected)."""
        self._select_run(run_id)

    def _select_run(self, run_id: str | None) -> None:
        if run_id == self.run_id:
            return
        with self.lock:
            self.run_id = run_id
            self.value_demon, self.shown = None, ()
        option = next((o for o, r in self._run_ids.items() if r == run_id), None)
        if option is not None and self.run.value != option:
            _set(self.run, option)
        self.changed.set()

    def set_demons(self, names: Sequence[str], with_shown: bool = True) -> None:
        """Rebuild the demon widgets for a newly chosen run (or when demons joined or left it); without
        `with_shown`, only the value map's dropdown (a stream run has no charts of shown demons)."""
        for handle in self._demon_handles:
            handle.remove()
        self._demon_handles, self._checkboxes = [], {}
        self._remove_charts()
        gui = self.server.gui
        with self.lock:  # keep what is still there (demons joined or left), else the first ones
            self.value_demon = self.value_demon if self.value_demon in names else (names[0] if names else None)
            ticked = [name for name in self.shown if name in names]
            self.shown = tuple(ticked or names[:DEFAULT_SHOWN])
        if self.value_demon is None:
            return
        value = gui.add_dropdown("Value map", tuple(names), initial_value=self.value_demon, order=20)
        value.on_update(lambda event: self._on_value_demon(event, value))
        self._demon_handles.append(value)
        if not with_shown:
            return
        folder = gui.add_folder("Demons shown", order=21)
        with folder:
            for name in names[:MAX_DEMON_CHECKBOXES]:
                box = gui.add_checkbox(name, name in self.shown)
                box.on_update(self._shown_callback(box, name))
                self._checkboxes[name] = box
        self._demon_handles.append(folder)

    def _on_value_demon(self, event: Any, handle: Any) -> None:
        if self._may_change(event):
            self._set_value_demon(handle.value)
        else:
            _set(handle, self.value_demon)

    def show_demons(self, names: Sequence[str]) -> None:
        """Label and chart these demons (the dashboard's selection; the first MAX_SHOWN of them)."""
        with self.lock:
            self.shown = tuple(dict.fromkeys(names))[:MAX_SHOWN]
        self._ticking = True  # the boxes follow; their callbacks must not undo the choice half-way
        try:
            for name, box in self._checkboxes.items():
                _set(box, name in self.shown)
        finally:
            self._ticking = False
        self.changed.set()

    def set_sensors(self, names: Sequence[str]) -> None:
        """The phase plane's axis choices for a run drawn as one (after `set_demons`, removed with its widgets)."""
        gui = self.server.gui
        with self.lock:
            self.phase_x = self.phase_x if self.phase_x in names else (names[0] if names else None)
            fallback = names[min(1, len(names) - 1)] if names else None
            self.phase_y = self.phase_y if self.phase_y in names else fallback
        for label, attribute, order, hint in (
            ("Phase plane x", "phase_x", 18, "the sensor along the plane's x axis"),
            ("Phase plane y", "phase_y", 19, "the sensor along y (the others held at their last readings)"),
        ):
            handle = gui.add_dropdown(label, tuple(names), initial_value=getattr(self, attribute), order=order,
                                      hint=hint)  # fmt: skip
            handle.on_update(self._sensor_callback(handle, attribute))
            self._demon_handles.append(handle)

    def _sensor_callback(self, handle: Any, attribute: str) -> Callable[[Any], None]:
        def changed(event: Any) -> None:
            if self._may_change(event):
                setattr(self, attribute, handle.value)
                self.changed.set()
            else:
                _set(handle, getattr(self, attribute))

        return changed

    def show_phase_state(self, received: int, learned: int) -> None:
        """A stream run's counters: it has no episodes, steps or return of its own."""
        _set(self.status, f"stream: {received} records received")
        _set(self.episode, 0)
        _set(self.step, learned)
        _set(self.total, learned)
        _set(self.episode_return, 0.0)

    def _set_value_demon(self, name: str) -> None:
        self.value_demon = name
        self.changed.set()

    def _shown_callback(self, box: Any, name: str) -> Callable[[Any], None]:
        return lambda event: self._on_shown(event, box, name)

    def _on_shown(self, event: Any, box: Any, name: str) -> None:
        if self._may_change(event):
            self._set_shown()
        else:
            _set(box, name in self.shown)

    def _set_shown(self) -> None:
        if self._ticking:
            return
        # A tick changes the demons with boxes; those beyond them that the dashboard chose stay.
        beyond = tuple(name for name in self.shown if name not in self._checkboxes)
        ticked = tuple(name for name, box in self._checkboxes.items() if box.value)
        self.shown = (ticked + beyond)[:MAX_SHOWN]
        self.changed.set()

    def _sync_speed(self, snapshot: ViewSnapshot) -> None:
        """Show the run's speed (it may change elsewhere, say over REST) without commanding it."""
        self._syncing = True
        try:
            for hz, full_speed in list(self._speed_inputs.values()):
                _set(full_speed, snapshot.hz is None)
                if snapshot.hz is not None:
                    _set(hz, int(np.clip(round(snapshot.hz), *SPEED_RANGE)))
        finally:
            self._syncing = False

    # ------------------------------------------------------------------------------------------
    # Readouts and charts

    def show_state(self, snapshot: ViewSnapshot) -> None:
        """Status, speed, episode, step and return of the snapshot (sent only when they change)."""
        self._sync_speed(snapshot)
        _set(self.status, snapshot.status)
        _set(self.episode, snapshot.episode)
        _set(self.step, snapshot.episode_step)
        _set(self.total, snapshot.total_steps)
        _set(self.episode_return, round(snapshot.episode_return, 3))

    def _remove_charts(self) -> None:
        if self._charts is not None:
            for chart in self._charts:
                chart.remove()
        self._charts, self._chart_names = None, ()

    def show_charts(self, snapshot: ViewSnapshot, names: Sequence[str]) -> None:
        """The predictions and RUPEE of `names` over the recent steps."""
        names = tuple(n for n in names if n in snapshot.history.predictions)
        if names != self._chart_names or len(snapshot.history.steps) < 2:
            self._remove_charts()
        if not names or len(snapshot.history.steps) < 2:
            return  # uPlot keeps a broken x range when it starts with fewer than two points
        steps = snapshot.history.steps.astype(float)
        predictions = (steps, *(snapshot.history.predictions[n] for n in names))
        rupee = (steps, *(snapshot.history.rupee[n] for n in names))
        if self._charts is None:
            gui = self.server.gui
            demon_order = [d.name for d in snapshot.spec.demons]
            scales: dict[str, viser.uplot.Scale] = {"x": {"time": False}}
            axes: tuple[viser.uplot.Axis, ...] = ({"label": "step"}, {"label": ""})
            self._charts = (
                gui.add_uplot(
                    predictions,
                    _series(names, demon_order),
                    title="Predictions",
                    scales=scales,
                    axes=axes,
                    aspect=1.6,
                    order=30,
                ),
                gui.add_uplot(
                    rupee, _series(names, demon_order), title="RUPEE", scales=scales, axes=axes, aspect=1.6, order=31
                ),
            )
            self._chart_names = names
        else:
            self._charts[0].data = predictions
            self._charts[1].data = rupee
