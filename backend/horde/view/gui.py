"""`ControlPanel`: the viser GUI of the live view (run and demon selectors, commands, readouts, charts).

The panel is shared by every browser that shows the view (a classroom watches one teacher's
choices). GUI callbacks run on viser's thread pool: they forward commands to the source and record
the selection, which the view thread reads at its next frame.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import viser
import viser.uplot

from horde.view.palette import demon_colour
from horde.view.source import ViewSnapshot, ViewSource

MAX_DEMON_CHECKBOXES = 12  # demons that can be ticked for labels and charts (the first ones)
MAX_SHOWN = 12  # demons labelled and charted at once (the dashboard may choose them among thousands)
DEFAULT_SHOWN = 3  # demons ticked when a run is chosen


def _series(names: Sequence[str], order: Sequence[str]) -> tuple[viser.uplot.Series, ...]:
    """uPlot series: the step axis, then one line per demon in its colour (by its place in `order`)."""
    series: list[viser.uplot.Series] = [{"label": "step"}]
    for name in names:
        series.append({"label": name, "stroke": demon_colour(order.index(name)), "width": 2})
    return tuple(series)


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

    def __init__(self, server: viser.ViserServer, source: ViewSource, on_view_mode: Callable[[bool], None]) -> None:
        self.server = server
        self.source = source
        self.on_view_mode = on_view_mode
        self.lock = threading.Lock()
        self.run_id: str | None = None
        self.value_demon: str | None = None
        self.shown: tuple[str, ...] = ()
        self.three_d = False
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
        # Minimized to a bar at first: embedded in the dashboard the panel would cover half the world, and
        # the dashboard has the same controls; one click on the bar opens it.
        gui.main_panel.minimize()
        self.run = gui.add_dropdown("Run", ("(none)",), order=0)
        self.run.on_update(lambda _: self._select_run(self._run_ids.get(self.run.value)))
        self.status = gui.add_text("Status", "", disabled=True, order=1)
        play, pause = gui.add_button("Play", order=2), gui.add_button("Pause", order=3)
        play.on_click(lambda _: self._command(self.source.play))
        pause.on_click(lambda _: self._command(self.source.pause))
        self.steps = gui.add_number("Steps per click", 1, min=1, max=10_000, step=1, order=4)
        step = gui.add_button("Step", order=5)
        step.on_click(lambda _: self._command(lambda run: self.source.step(run, int(self.steps.value))))
        reset = gui.add_button("Reset", order=6)
        reset.on_click(lambda _: self._command(self.source.reset))
        self.hz = gui.add_slider("Speed (steps/s)", 1, 200, 1, 10, order=7)
        self.full_speed = gui.add_checkbox("Full speed", False, hint="as fast as possible", order=8)
        self.hz.on_update(lambda _: self._set_hz())
        self.full_speed.on_update(lambda _: self._set_hz())
        self.episode = gui.add_number("Episode", 0, disabled=True, order=9)
        self.step = gui.add_number("Step", 0, disabled=True, order=10)
        self.total = gui.add_number("Total steps", 0, disabled=True, order=11)
        self.episode_return = gui.add_number("Return", 0.0, step=0.001, disabled=True, order=12)
        self.view_button = gui.add_button("Tilt to 3-D", order=13)
        self.view_button.on_click(lambda _: self._toggle_view())
        self._syncing = False  # True while the view itself sets widget values

    def _command(self, command: Callable[[str], None]) -> None:
        if self.run_id is not None:
            command(self.run_id)
            self.changed.set()

    def _set_hz(self) -> None:
        if self._syncing:
            return
        self._command(lambda run: self.source.set_hz(run, None if self.full_speed.value else float(self.hz.value)))

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

    def set_demons(self, names: Sequence[str]) -> None:
        """Rebuild the demon widgets for a newly chosen run (or when demons joined or left it)."""
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
        value.on_update(lambda _: self._set_value_demon(value.value))
        self._demon_handles.append(value)
        folder = gui.add_folder("Demons shown", order=21)
        with folder:
            for name in names[:MAX_DEMON_CHECKBOXES]:
                box = gui.add_checkbox(name, name in self.shown)
                box.on_update(lambda _: self._set_shown())
                self._checkboxes[name] = box
        self._demon_handles.append(folder)

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

    def _set_value_demon(self, name: str) -> None:
        self.value_demon = name
        self.changed.set()

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
            _set(self.full_speed, snapshot.hz is None)
            if snapshot.hz is not None:
                _set(self.hz, int(np.clip(round(snapshot.hz), 1, 200)))
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
