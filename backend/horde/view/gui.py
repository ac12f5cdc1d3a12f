"""`ControlPanel`: one browser's viser GUI (run and demon selectors, commands, readouts, charts).

Every browser (viser client) has a panel of its own, built in its own `client.gui`. Its selectors (run,
value map, demons shown, phase-plane axes, 3-D, large text) change what that browser sees and nothing
else, so anyone may use them. Its commands (`horde.view.commands.RunCommands`) change a run, which every
viewer sees: they follow the browser's token (runs/access.py).

Threads. GUI callbacks run on viser's thread pool; they only record what the browser chose (under
`lock`) and wake the view thread (`changed`), or forward a command to the source. Every change to the
panel's widgets (adding, removing, setting values) is made by the view thread (the `sync_*`, `set_*`
and `show_*` methods), so no callback, route or frame ever writes to a widget that another thread has
just removed; `set_value` and `remove` also skip widgets that viser itself has removed (a client that
left). An assignment made by the view thread calls the widget's callbacks with no client: they ignore it.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Sequence
from typing import Any

import viser
import viser.uplot

from horde.runs.access import Access
from horde.view.commands import RunCommands, from_browser, remove, removed, set_value
from horde.view.palette import demon_colour
from horde.view.source import ViewSnapshot, ViewSource

MAX_DEMON_CHECKBOXES = 12  # demons that can be ticked for labels and charts (the first ones)
MAX_SHOWN = 12  # demons labelled and charted at once (the dashboard may choose them among thousands)
DEFAULT_SHOWN = 3  # demons ticked when a run is chosen
LARGE_SCALE = 1.5  # Large text: the panel's and the labels' size, times the normal one
# Large text for the panel: viser's panel is drawn with Mantine, whose sizes are in rem, so a larger root font
# scales the whole panel (its text, inputs and charts' titles). Put into the page by an HTML widget's <style>.
LARGE_PANEL_STYLE = f"<style>html {{ font-size: {100 * LARGE_SCALE:g}%; }}</style>"


def _series(names: Sequence[str], order: Sequence[str]) -> tuple[viser.uplot.Series, ...]:
    """uPlot series: the step axis, then one line per demon in its colour (by its place in `order`)."""
    series: list[viser.uplot.Series] = [{"label": "step"}]
    for name in names:
        series.append({"label": name, "stroke": demon_colour(order.index(name)), "width": 2})
    return tuple(series)


class ControlPanel:
    """The GUI of one browser (viser client).

    Args:
        client: the viser client whose own GUI this is.
        source: where commands go.
        changed: set when the browser's choices change (the view thread redraws at once).
        access: the server's tokens and owners (None: no roles, every browser may command every run).
    """

    def __init__(
        self, client: viser.ClientHandle, source: ViewSource, changed: threading.Event, access: Access | None = None
    ) -> None:
        self.client = client
        self.gui = client.gui
        self.source = source
        self.changed = changed
        self.access = access
        self.lock = threading.Lock()
        # What the browser chose (written by callbacks and by the dashboard's choices, read by the view thread).
        self.run_id: str | None = None
        self.value_demon: str | None = None
        self.shown: tuple[str, ...] = ()
        self.three_d = False
        self.large = False
        self.phase_x: str | None = None  # the sensors along a phase plane's axes
        self.phase_y: str | None = None
        # What the widgets show (the view thread's).
        self._run_ids: dict[str, str] = {}  # dropdown option -> run id
        self._label: str | None = None
        self._three_d_shown = False
        self._large_style: viser.GuiHtmlHandle | None = None
        self._demon_handles: list[Any] = []
        self._checkboxes: dict[str, viser.GuiCheckboxHandle] = {}
        self._charts: tuple[viser.GuiUplotHandle, viser.GuiUplotHandle] | None = None
        self._chart_names: tuple[str, ...] = ()
        self._build()

    # ------------------------------------------------------------------------------------------
    # Fixed widgets

    def _build(self) -> None:
        gui = self.gui
        gui.configure_theme(control_width="large")
        # Minimized to a bar at first: embedded in the dashboard the panel would cover half the world, and
        # the dashboard has the same controls; one click on the bar opens it. Its title names the run shown.
        gui.main_panel.minimize()
        self.run = gui.add_dropdown("Run", ("(none)",), order=0)
        self.run.on_update(self._on_run)
        self.commands = RunCommands(self.client, self.source, self.changed, self.access, lambda: self.run_id)
        self.status = gui.add_text("Status", "", disabled=True, order=1)
        self.episode = gui.add_number("Episode", 0, disabled=True, order=9)
        self.step = gui.add_number("Step", 0, disabled=True, order=10)
        self.total = gui.add_number("Total steps", 0, disabled=True, order=11)
        self.episode_return = gui.add_number("Return", 0.0, step=0.001, disabled=True, order=12)
        self.view_button = gui.add_button("Tilt to 3-D", order=13)
        self.view_button.on_click(self._on_tilt)
        self.large_box = gui.add_checkbox("Large text", False, hint="larger labels and panel", order=14)
        self.large_box.on_update(self._on_large)

    # ------------------------------------------------------------------------------------------
    # Callbacks (viser's thread pool): record the choice, wake the view thread

    def _on_run(self, event: Any) -> None:
        if from_browser(event):
            self._choose_run(self._run_ids.get(self.run.value))

    def _on_tilt(self, event: Any) -> None:
        if from_browser(event):
            with self.lock:
                self.three_d = not self.three_d
            self.changed.set()

    def _on_large(self, event: Any) -> None:
        if from_browser(event):
            with self.lock:
                self.large = bool(self.large_box.value)
            self.changed.set()

    def _choose_run(self, run_id: str | None) -> None:
        with self.lock:
            if run_id == self.run_id:
                return
            self.run_id = run_id
            self.value_demon, self.shown = None, ()
        self.changed.set()

    def _value_callback(self, handle: Any) -> Callable[[Any], None]:
        def chosen(event: Any) -> None:
            if from_browser(event):
                with self.lock:
                    self.value_demon = handle.value
                self.changed.set()

        return chosen

    def _shown_callback(self) -> Callable[[Any], None]:
        def ticked(event: Any) -> None:
            if not from_browser(event):
                return
            with self.lock:  # a tick changes the demons with boxes; those beyond them that the dashboard chose stay
                beyond = tuple(name for name in self.shown if name not in self._checkboxes)
                boxes = tuple(name for name, box in self._checkboxes.items() if box.value)
                self.shown = (boxes + beyond)[:MAX_SHOWN]
            self.changed.set()

        return ticked

    def _sensor_callback(self, handle: Any, attribute: str) -> Callable[[Any], None]:
        def chosen(event: Any) -> None:
            if from_browser(event):
                with self.lock:
                    setattr(self, attribute, handle.value)
                self.changed.set()

        return chosen

    # ------------------------------------------------------------------------------------------
    # The view thread: the widgets follow the choices

    def choose(self, run_id: str, demons: Sequence[str] | None, large: bool | None, secret: str | None) -> None:
        """What this browser's dashboard chose (its run, demons, large text, token): taken as the browser's own; the
        token replaces any typed into the panel (the tab's choice is its browsers')."""
        with self.lock:
            if run_id != self.run_id:
                self.run_id, self.value_demon, self.shown = run_id, None, ()
            if demons is not None:
                self.shown = tuple(dict.fromkeys(demons))[:MAX_SHOWN]
            if large is not None:
                self.large = large
            self.commands.secret = secret  # the tab's token is its browsers' (none: they command nothing)
        self.changed.set()

    def set_runs(self, runs: Sequence[tuple[str, str]]) -> None:
        """Offer these runs; the first one is chosen when none is (or the chosen one is gone)."""
        options = {(run_id if label in ("", run_id) else f"{label} [{run_id}]"): run_id for run_id, label in runs}
        if options != self._run_ids:
            self._run_ids = options
            self.run.options = tuple(options) or ("(none)",)
        if self.run_id not in options.values():
            first = next(iter(options.values()), None)
            with self.lock:
                self.run_id, self.value_demon, self.shown = first, None, ()
        current = next((o for o, r in options.items() if r == self.run_id), None)
        if current is not None:
            set_value(self.run, current)
        self._name_run(current)

    def _name_run(self, option: str | None) -> None:
        """The panel's title names the run shown (its bar too, minimized as it starts)."""
        label = f"Showing {option}" if option is not None else "Showing no run"
        if label != self._label:
            self._label = label
            self.gui.set_panel_label(label)

    def sync_looks(self) -> tuple[bool, bool]:
        """The tilt button's label and the large-text style follow the choices; (3-D changed, large changed)."""
        three_d_changed = self.three_d != self._three_d_shown
        if three_d_changed:
            self._three_d_shown = self.three_d
            self.view_button.label = "Top-down 2-D" if self.three_d else "Tilt to 3-D"
        set_value(self.large_box, self.large)
        large_changed = self.large != (self._large_style is not None)
        if large_changed:
            if self._large_style is not None:
                remove(self._large_style)
                self._large_style = None
            else:
                self._large_style = self.gui.add_html(LARGE_PANEL_STYLE, order=99)
        return three_d_changed, large_changed

    def set_demons(self, names: Sequence[str], with_shown: bool = True) -> None:
        """Rebuild the demon widgets for a newly chosen run (or when demons joined or left it); without
        `with_shown`, only the value map's dropdown (a stream run has no charts of shown demons)."""
        for handle in self._demon_handles:
            remove(handle)
        self._demon_handles = []
        self._remove_charts()
        gui = self.gui
        with self.lock:  # keep what is still there (demons joined or left), else the first ones
            self.value_demon = self.value_demon if self.value_demon in names else (names[0] if names else None)
            ticked = [name for name in self.shown if name in names]
            self.shown = tuple(ticked or names[:DEFAULT_SHOWN])
            self._checkboxes = {}
        if self.value_demon is None:
            return
        value = gui.add_dropdown("Value map", tuple(names), initial_value=self.value_demon, order=20)
        value.on_update(self._value_callback(value))
        self._demon_handles.append(value)
        if not with_shown:
            return
        folder = gui.add_folder("Demons shown", order=21)
        boxes = {}
        with folder:
            for name in names[:MAX_DEMON_CHECKBOXES]:
                box = gui.add_checkbox(name, name in self.shown)
                box.on_update(self._shown_callback())
                boxes[name] = box
        with self.lock:
            self._checkboxes = boxes
        self._demon_handles.append(folder)

    def sync_demons(self) -> None:
        """The value map's dropdown and the boxes show the demons chosen (say, by the dashboard)."""
        if self._demon_handles and self.value_demon is not None:
            set_value(self._demon_handles[0], self.value_demon)
        for name, box in list(self._checkboxes.items()):
            set_value(box, name in self.shown)

    def set_sensors(self, names: Sequence[str]) -> None:
        """The phase plane's axis choices for a run drawn as one (after `set_demons`, removed with its widgets)."""
        with self.lock:
            self.phase_x = self.phase_x if self.phase_x in names else (names[0] if names else None)
            fallback = names[min(1, len(names) - 1)] if names else None
            self.phase_y = self.phase_y if self.phase_y in names else fallback
        for label, attribute, order, hint in (
            ("Phase plane x", "phase_x", 18, "the sensor along the plane's x axis"),
            ("Phase plane y", "phase_y", 19, "the sensor along y (the others held at their last readings)"),
        ):
            handle = self.gui.add_dropdown(label, tuple(names), initial_value=getattr(self, attribute), order=order,
                                           hint=hint)  # fmt: skip
            handle.on_update(self._sensor_callback(handle, attribute))
            self._demon_handles.append(handle)

    # ------------------------------------------------------------------------------------------
    # Readouts and charts (the view thread's)

    def show_phase_state(self, received: int, learned: int) -> None:
        """A stream run's counters: it has no episodes, steps or return of its own."""
        set_value(self.status, f"stream: {received} records received")
        set_value(self.episode, 0)
        set_value(self.step, learned)
        set_value(self.total, learned)
        set_value(self.episode_return, 0.0)

    def show_state(self, snapshot: ViewSnapshot) -> None:
        """Status, speed, episode, step and return of the snapshot (sent only when they change)."""
        self.commands.show_speed(snapshot.hz)
        set_value(self.status, snapshot.status)
        set_value(self.episode, snapshot.episode)
        set_value(self.step, snapshot.episode_step)
        set_value(self.total, snapshot.total_steps)
        set_value(self.episode_return, round(snapshot.episode_return, 3))

    def _remove_charts(self) -> None:
        if self._charts is not None:
            for chart in self._charts:
                remove(chart)
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
            gui = self.gui
            demon_order = [d.name for d in snapshot.spec.demons]
            scales: dict[str, viser.uplot.Scale] = {"x": {"time": False}}
            axes: tuple[viser.uplot.Axis, ...] = ({"label": "step"}, {"label": ""})
            self._charts = (
                gui.add_uplot(predictions, _series(names, demon_order), title="Predictions", scales=scales,
                              axes=axes, aspect=1.6, order=30),
                gui.add_uplot(rupee, _series(names, demon_order), title="RUPEE", scales=scales, axes=axes,
                              aspect=1.6, order=31),
            )  # fmt: skip
            self._chart_names = names
        else:
            for chart, data in zip(self._charts, (predictions, rupee), strict=True):
                if not removed(chart):
                    chart.data = data
