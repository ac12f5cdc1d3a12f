"""LiveView without a browser: its port, one refresh of a client's scene and panel, the camera, the
applier, and each client's own view (raw WebSocket clients, tests/view/viewers.py).

The view runs on the production path: the server's RunManager behind ManagerSource.
"""

from __future__ import annotations

import itertools
import socket
import threading
import time
import urllib.request
from collections import OrderedDict
from collections.abc import Iterator, Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from horde.runs.manager import RunManager
from horde.scenarios import load_scenario
from horde.spec import RunSpec
from horde.view import LiveView, ManagerSource, camera
from horde.view.apply import SceneApplier
from horde.view.nodes import Node
from horde.view.source import ViewSnapshot
from horde.view.viewer import Frame
from polling import wait_until
from serving import free_port

from .viewers import RawClient, started_by_hand

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
TAB = "dashboard-tab-1"  # a dashboard tab's key


def runs_of(*specs: RunSpec, source: type[ManagerSource] = ManagerSource) -> ManagerSource:
    """A source over a fresh run manager (no store) holding one created run of each spec, in order."""
    manager = RunManager()
    for spec in specs:
        manager.create(spec, hz=50.0)
    return source(manager)


@pytest.fixture
def source() -> Iterator[ManagerSource]:
    source = runs_of(load_scenario(SCENARIOS / "experiment1.toml"))
    yield source
    source.manager.stop()


def test_the_view_reports_the_port_it_really_got(source: ManagerSource) -> None:
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = int(taken.getsockname()[1])
        view = LiveView(source, port=port)
        view.start()
        try:
            assert view.port != port
            assert view.url == f"http://127.0.0.1:{view.port}/"
            with urllib.request.urlopen(view.url, timeout=10) as response:
                assert response.status == 200
        finally:
            view.stop()
    with pytest.raises(RuntimeError):
        _ = view.port


def test_one_refresh_draws_the_chosen_run(source: ManagerSource) -> None:
    view = started_by_hand(source)
    ((run, label),) = source.list_runs()
    assert label == "experiment1"
    try:
        viewer = RawClient(view).viewer
        source.step(run, 5)
        view.refresh()
        snap = source.snapshot(run)
        drawn = viewer.applier.drawn
        assert {"/world/floor", "/regions/goal", "/agent", "/predictions", "/value_map/texture"} <= set(drawn)
        assert "/value_map/arrows" in drawn  # the first demon, base, is a control demon
        assert drawn["/agent"][0].position[:2] == pytest.approx(((snap.x + 50) / 50, (snap.y + 50) / 50))
        assert viewer.panel.run_id == run
        assert viewer.panel.value_demon == "base"
        assert viewer.panel.shown == ("base", "steps_to_end")
        assert viewer.panel.total.value == 5
        assert viewer.panel._label == f"Showing experiment1 [{run}]", "the panel's title names the run it shows"
        assert tuple(viewer.client.camera.up_direction) == pytest.approx((0.0, 1.0, 0.0))
    finally:
        view.stop()


def test_the_default_lights_cast_no_shadow(source: ManagerSource) -> None:
    """A shadow map costs a GPU-less browser a quarter of each frame, and nothing in the flat world casts one."""
    view = started_by_hand(source)
    try:
        client = RawClient(view)
        lights = wait_until(
            lambda: [m for m in client.sent() if m["type"] == "EnableLightsMessage"], "the lights' message", 10.0
        )
        assert [(m["enabled"], m["cast_shadow"]) for m in lights] == [(True, False)]
        client.close()
    finally:
        view.stop()


def test_the_default_camera_looks_straight_down_with_y_up_and_the_tilt_keeps_z_up() -> None:
    world = load_scenario(SCENARIOS / "experiment1.toml").world
    top = camera.top_down(world)
    assert top.position[:2] == top.look_at[:2] and top.position[2] > 0.0 and top.look_at[2] == 0.0
    assert top.up == (0.0, 1.0, 0.0)
    tilted = camera.tilted(world)
    assert tilted.up == (0.0, 0.0, 1.0)
    assert tilted.position[1] < tilted.look_at[1] and tilted.position[2] > 0.0


class FakeHandle:
    def __init__(self, log: list[tuple[str, str]], name: str) -> None:
        self.log, self.name = log, name

    def remove(self) -> None:
        self.log.append(("remove", self.name))

    def __setattr__(self, key: str, value: Any) -> None:
        if key == "position":
            self.log.append(("move", self.name))
        object.__setattr__(self, key, value)


class FakeScene:
    def __init__(self) -> None:
        self.log: list[tuple[str, str]] = []

    def add_box(self, name: str, **_: Any) -> FakeHandle:
        self.log.append(("add", name))
        return FakeHandle(self.log, name)

    add_icosphere = add_box


def test_the_applier_sends_only_what_changed() -> None:
    fake = FakeScene()
    applier = SceneApplier(fake)  # type: ignore[arg-type]
    box = Node("/a", "box", (0.0, 0.0, 0.0), (1.0, 1.0, 1.0), (1, 2, 3))
    sphere = Node("/b", "sphere", (0.0, 0.0, 0.0), (1.0, 0.0, 0.0))
    applier.apply([box, sphere], "world")
    applier.apply([box, sphere], "world")
    assert fake.log == [("add", "/a"), ("add", "/b")]
    fake.log.clear()
    moved = Node("/b", "sphere", (1.0, 0.0, 0.0), (1.0, 0.0, 0.0))
    recoloured = Node("/a", "box", (0.0, 0.0, 0.0), (1.0, 1.0, 1.0), (9, 9, 9))
    applier.apply([recoloured, moved], "world")
    assert fake.log == [("add", "/a"), ("move", "/b")]
    fake.log.clear()
    applier.apply([], "other")  # another owner's nodes stay
    applier.apply([moved], "world")
    assert fake.log == [("remove", "/a")]
    assert np.allclose(applier.drawn["/b"][0].position, (1.0, 0.0, 0.0))


class JoiningSource(ManagerSource):
    """A ManagerSource whose run can be made to report another spec (demons joining a live run)."""

    spec_override: RunSpec | None = None

    def snapshot(self, run_id: str, demons: Sequence[str] | None = None) -> ViewSnapshot:
        snap = super().snapshot(run_id, demons)
        return snap if self.spec_override is None else replace(snap, spec=self.spec_override)


def test_a_frame_remakes_what_it_keeps_recent_at_most_once_a_period() -> None:
    kept: Any = OrderedDict()
    made: list[tuple[float, int]] = []

    def at(now: float, state: int) -> tuple[float, int]:
        def make() -> tuple[float, int]:
            made.append((now, state))
            return made[-1]

        return Frame(None, now, kept).recent(("map",), state, 0.5, make)  # type: ignore[arg-type]

    assert at(0.0, 1) == (0.0, 1)
    assert at(0.0, 2) == (0.0, 1), "the same frame (another browser): the same answer"
    assert at(0.4, 2) == (0.0, 1), "moved, but less than a period ago"
    assert at(0.5, 2) == (0.5, 2)
    assert at(9.0, 2) == (0.5, 2), "not moved since: kept however old"
    assert made == [(0.0, 1), (0.5, 2)]


class CountingSource(ManagerSource):
    """A ManagerSource that counts the value maps the view asks of the runs' workers."""

    value_maps = 0

    def value_map(self, run_id: str, demon: str, resolution: int) -> np.ndarray:
        self.value_maps += 1
        return super().value_map(run_id, demon, resolution)


def test_the_browsers_of_one_run_share_one_value_map_a_period() -> None:
    """Many browsers of a moving run cost its worker the value maps of one: the map is remade at most `map_hz`
    times a second for every browser that shows it, whenever each connected, and each draws the same nodes (one
    PNG). Before, each browser kept its own clock: browsers that came in different frames asked for their own
    maps, about one per browser and period (thirty browsers, thirty maps every third of a second)."""
    source = runs_of(load_scenario(SCENARIOS / "experiment1.toml"), source=CountingSource)
    assert isinstance(source, CountingSource)
    run = source.list_runs()[0][0]
    map_hz = 4.0
    view = started_by_hand(source, map_hz=map_hz)
    try:
        source.play(run)  # 50 steps a second: the run moves between frames
        clients = []
        for k in range(3):  # each browser comes in a frame of its own, a third of a period after the last
            clients.append(RawClient(view, f"dashboard-tab-{k}"))
            view.show(f"dashboard-tab-{k}", run)
            view.refresh()
            time.sleep(1.0 / map_hz / 3)
        drawn = clients[0].viewer.applier.drawn
        names = ("/trail", "/value_map/texture")
        frames = []  # the first browser's trail and map in each frame: (node, handle), None where not drawn
        source.value_maps = 0
        began = time.monotonic()
        while time.monotonic() - began < 1.5:
            view.refresh()
            frames.append({name: drawn[name][:2] if name in drawn else None for name in names})
            time.sleep(0.01)
        elapsed = time.monotonic() - began
        assert 1 <= source.value_maps <= elapsed * map_hz + 1, f"{source.value_maps} maps in {elapsed:.2f} s"
        textures = [c.viewer.applier.drawn["/value_map/texture"][0] for c in clients]
        assert all(texture is textures[0] for texture in textures), "every browser draws the one map"
        # A new trail or map updates the browser's node in place: between two frames that both draw it, a new node
        # keeps the handle. (The trail is not drawn at an episode's first step, `scene.agent_nodes`: a trail drawn
        # again after that is a node anew, rightly.)
        for name in names:
            updates = 0
            for before, after in itertools.pairwise(frames):
                if before[name] is not None and after[name] is not None and after[name][0] is not before[name][0]:
                    assert after[name][1] is before[name][1], f"{name}: a new node, not an update in place"
                    updates += 1
            assert updates >= 1, f"{name} was never redrawn"
    finally:
        view.stop()
        source.manager.stop()


def test_demons_joining_the_run_shown_keep_the_choices_still_possible() -> None:
    spec = load_scenario(SCENARIOS / "experiment1.toml")
    source = runs_of(spec, source=JoiningSource)
    assert isinstance(source, JoiningSource)
    view = started_by_hand(source)
    try:
        viewer = RawClient(view).viewer
        view.refresh()
        viewer.panel.value_demon = "steps_to_end"
        extra = spec.demons[1].model_copy(update={"name": "extra"})
        source.spec_override = spec.model_copy(update={"demons": [*spec.demons, extra]})
        view.refresh()
        assert viewer.panel.value_demon == "steps_to_end"
        assert viewer.panel.shown == ("base", "steps_to_end")
        assert list(viewer.panel._checkboxes) == ["base", "steps_to_end", "extra"]
        assert "/value_map/arrows" not in viewer.applier.drawn  # steps_to_end is no control demon
    finally:
        view.stop()
        source.manager.stop()


def test_the_dashboard_chooses_the_demons_labelled_beyond_the_checkboxes() -> None:
    spec = load_scenario(SCENARIOS / "experiment1.toml")
    many = [spec.demons[1].model_copy(update={"name": f"d{i}"}) for i in range(20)]
    source = runs_of(spec.model_copy(update={"demons": [*spec.demons, *many]}), source=JoiningSource)
    view = started_by_hand(source)
    try:
        client = RawClient(view, TAB)
        panel = client.viewer.panel
        run = source.list_runs()[0][0]
        view.show(TAB, run, ["d17", "base", "d17"])
        view.refresh()
        assert panel.shown == ("d17", "base")  # d17 has no checkbox (only the first 12 have)
        assert "d17" not in panel._checkboxes and panel._checkboxes["base"].value
        label = next(node for node in client.viewer.applier.drawn["/predictions"] if node.text)
        assert "d17" in label.text and "steps_to_end" not in label.text
        # A tick in the browser keeps the dashboard's choice beyond the boxes.
        client.update_gui(panel._checkboxes["steps_to_end"], True)
        wait_until(lambda: panel.shown == ("base", "steps_to_end", "d17"), "the tick to reach the panel", 10.0)
    finally:
        view.stop()
        source.manager.stop()


def test_a_stream_run_is_drawn_as_a_phase_plane_in_the_same_view() -> None:
    from tests.worlds.test_streams import stream_spec

    from horde.runs.stream_run import StreamRuns
    from horde.view.source import CommandRefusedError

    manager, streams = RunManager(), StreamRuns()
    manager.create(load_scenario(SCENARIOS / "experiment1.toml"), hz=50.0)
    stream = streams.create(RunSpec.model_validate({**stream_spec(), "name": "robot"}))
    source = ManagerSource(manager, streams)
    view = started_by_hand(source)
    try:
        client = RawClient(view, TAB)
        panel = client.viewer.panel
        grid_run = source.list_runs()[0][0]
        assert source.list_runs()[1] == (stream.id, "stream robot")
        view.refresh()  # the grid run first
        assert "/world/floor" in client.viewer.applier.drawn
        view.show(TAB, stream.id)
        stream.push([{"observation": [0.1 * k % 1, 0.5 - 0.01 * k, 30.0], "action": k % 3} for k in range(60)])
        view.refresh()
        drawn = client.viewer.applier.drawn
        assert "/world/floor" not in drawn, "the grid run's world is gone"
        assert {"/phase/map", "/phase/trail", "/phase/agent", "/phase/x_label", "/phase/y_label"} <= set(drawn)
        assert drawn["/phase/x_label"][0].text == "light [0, 1]"
        assert drawn["/phase/y_label"][0].text == "wheel [-1, 1]"
        assert drawn["/phase/title"][0].text.startswith("light_if_left: ")
        assert panel.total.value == 60 and panel.status.value == "stream: 60 records received"
        assert panel._checkboxes == {}, "no 'Demons shown' boxes: a stream run has no charts of them"
        # The agent sits at the last (x, y) reading: light 0.9 (59 * 0.1 mod 1), wheel 0.5 - 0.59.
        agent = drawn["/phase/agent"][0].position
        assert agent[:2] == pytest.approx(((0.9 - 0.5) * 10.0, (-0.09 + 1.0) / 2.0 * 10.0 - 5.0))
        panel.phase_y, panel.value_demon = "heat", "wheel_g0.9"
        assert panel.commands._built_for == (stream.id, False), "a stream run has no commands"
        view.refresh()
        assert client.viewer.applier.drawn["/phase/y_label"][0].text == "heat [20, 40]"
        assert client.viewer.applier.drawn["/phase/title"][0].text.startswith("wheel_g0.9: ")
        with pytest.raises(CommandRefusedError, match="stream run"):
            source.play(stream.id)
        view.show(TAB, grid_run)
        view.refresh()
        assert "/world/floor" in client.viewer.applier.drawn and "/phase/map" not in client.viewer.applier.drawn
    finally:
        view.stop()
        manager.stop()


def test_a_gymnasium_run_is_drawn_as_a_phase_plane_with_its_trail_and_commands() -> None:
    from tests.server.test_gym_runs import gym_spec

    from horde.runs.snapshot import Snapshot, restore
    from horde.worlds.phase_plane import axis_of, phase_plane

    manager = RunManager()
    run_id = manager.create(RunSpec.model_validate(gym_spec())).id
    source = ManagerSource(manager)
    view = started_by_hand(source)
    view.map_hz = 1e6  # every frame redraws the plane
    try:
        client = RawClient(view, TAB)
        panel = client.viewer.panel
        assert source.is_phase(run_id) and not source.is_stream(run_id)
        view.show(TAB, run_id)
        view.refresh()  # the episode's first state starts the trail
        positions = [manager.get(run_id).view.sensors[:2].copy()]  # type: ignore[index]
        for _ in range(5):  # the view samples the run's sensors once per frame, as the grid's trail
            source.step(run_id, 7)  # a GUI command reaches the run (streams refuse them)
            positions.append(manager.get(run_id).view.sensors[:2].copy())  # type: ignore[index]
            view.refresh()
        drawn = client.viewer.applier.drawn
        assert "/world/floor" not in drawn
        assert {"/phase/map", "/phase/trail", "/phase/agent"} <= set(drawn)
        assert drawn["/phase/x_label"][0].text == "position [-1.2, 0.6]"
        assert drawn["/phase/y_label"][0].text == "velocity [-0.07, 0.07]"
        assert panel.total.value == 35 and panel.status.value == "paused"
        assert panel._checkboxes, "a live run's demons can be shown in the charts"
        assert panel.commands.folder is not None, "a live Gymnasium run takes commands (no roles here)"
        # The agent sits at the run's last (position, velocity); the trail holds each frame's reading.
        segments = drawn["/phase/trail"][0].points  # [N - 1, 2, 3]
        # The run's weights, out of its worker: its snapshot, restored here.
        weights = restore(Snapshot.model_validate_json(manager.get(run_id).snapshot())).sim
        x, y = axis_of(weights.horde, "position"), axis_of(weights.horde, "velocity")
        scene = np.array([((p - x.low) / (x.high - x.low) - 0.5, (v - y.low) / (y.high - y.low) - 0.5)
                          for p, v in positions]) * 10.0  # fmt: skip
        np.testing.assert_allclose(segments[:, 0, :2], scene[:-1])
        np.testing.assert_allclose(segments[:, 1, :2], scene[1:])
        assert drawn["/phase/agent"][0].position[:2] == pytest.approx(tuple(scene[-1]))
        # The value map is the demon's prediction over the plane, the other sensors held at the agent's.
        snapshot = source.phase_snapshot(run_id, "velocity_g0.9", "position", "velocity", 8)
        expected_map = phase_plane(weights.horde, weights.horde_state, "velocity_g0.9", x, y, weights.sensors, 8)
        np.testing.assert_array_equal(snapshot.values, expected_map)
        assert np.ptp(snapshot.values) > 0, "a learned velocity demon varies over the plane"
    finally:
        view.stop()
        manager.stop()


def test_each_client_sees_its_own_run_and_changes_nothing_another_sees() -> None:
    spec = load_scenario(SCENARIOS / "experiment1.toml")
    source = runs_of(spec.model_copy(update={"name": "first"}), spec.model_copy(update={"name": "second"}))
    first, second = (run for run, _ in source.list_runs())
    view = started_by_hand(source)
    try:
        teacher, student, own = RawClient(view, TAB), RawClient(view, "dashboard-tab-2"), RawClient(view)
        view.show(TAB, first)
        view.show("dashboard-tab-2", second)
        source.step(second, 3)
        view.refresh()
        assert teacher.viewer.panel.run_id == first and student.viewer.panel.run_id == second
        assert teacher.viewer.panel.run.value == f"first [{first}]"
        assert teacher.viewer.panel._label == f"Showing first [{first}]"
        assert student.viewer.panel._label == f"Showing second [{second}]"
        assert student.viewer.panel.total.value == 3 and teacher.viewer.panel.total.value == 0
        assert view.shown_run(TAB) == first and view.shown_run("dashboard-tab-2") == second
        # A hand-written client changes its own Run dropdown: only its own view follows.
        own.update_gui(own.viewer.panel.run, f"second [{second}]")
        wait_until(lambda: own.viewer.panel.run_id == second, "the raw client's own view to switch")
        view.refresh()
        assert own.viewer.panel._label == f"Showing second [{second}]"
        assert teacher.viewer.panel.run_id == first and teacher.viewer.panel.run.value == f"first [{first}]"
        # Nor can it reach another client's widgets: viser routes a client's GUI updates to its own GUI.
        own.update_gui(teacher.viewer.panel.run, f"second [{second}]")
        view.show("dashboard-tab-2", first)  # the other tab switching: the teacher's view stays
        view.refresh()
        assert teacher.viewer.panel.run_id == first and student.viewer.panel.run_id == first
        view.show(TAB, second)
        view.refresh()
        assert teacher.viewer.panel.run_id == second and student.viewer.panel.run_id == first
        assert teacher.viewer.applier.drawn["/agent"][0].position != student.viewer.applier.drawn["/agent"][0].position
        # A browser of a tab that connects later starts on that tab's choice.
        late = RawClient(view, TAB)
        view.refresh()
        assert late.viewer.panel.run_id == second
    finally:
        view.stop()
        source.manager.stop()


def test_a_key_that_is_not_one_is_ignored() -> None:
    source = runs_of(load_scenario(SCENARIOS / "experiment1.toml"))
    view = started_by_hand(source)
    try:
        assert RawClient(view, "bad%20key%21").viewer.key is None
        assert RawClient(view, "short").viewer.key is None
        assert RawClient(view, TAB).viewer.key == TAB
    finally:
        view.stop()
        source.manager.stop()


def test_large_text_redraws_one_clients_labels_larger_and_styles_its_panel() -> None:
    source = runs_of(load_scenario(SCENARIOS / "experiment1.toml"))
    run = source.list_runs()[0][0]
    view = started_by_hand(source)
    try:
        big, small = RawClient(view, TAB), RawClient(view)
        view.show(TAB, run, large=True)
        view.refresh()
        assert big.viewer.applier.label_scale == 1.5 and small.viewer.applier.label_scale == 1.0
        label = big.viewer.applier.drawn["/region_labels/goal"][1]
        assert label.font_screen_scale == 1.5, "the label itself was drawn larger"
        assert small.viewer.applier.drawn["/region_labels/goal"][1].font_screen_scale == 1.0
        assert big.viewer.panel._large_style is not None and small.viewer.panel._large_style is None
        assert big.viewer.panel.large_box.value is True
        small.update_gui(small.viewer.panel.large_box, True)  # the standalone view's own checkbox
        wait_until(lambda: small.viewer.panel.large, "the tick to reach the panel", 10.0)
        view.refresh()
        assert small.viewer.applier.drawn["/region_labels/goal"][1].font_screen_scale == 1.5
        view.show(TAB, run, large=False)
        view.refresh()
        assert big.viewer.applier.drawn["/region_labels/goal"][1].font_screen_scale == 1.0
        assert big.viewer.panel._large_style is None
    finally:
        view.stop()
        source.manager.stop()


def test_choices_and_clients_coming_and_going_never_raise_into_a_caller_or_the_view_thread(
    caplog: pytest.LogCaptureFixture,
) -> None:
    """The failure of the first try at a view per viewer: a dashboard's choice (POST /api/view) assigned to a
    checkbox the view thread had just removed while rebuilding the panel for another run, and the route
    answered 500 ("Cannot assign to 'value' on a removed GuiCheckboxHandle"). Here choices alternate runs
    (each with its own demons) as fast as they come, clients connect and leave mid-frame, and neither the
    callers of `show` nor the view thread may see an exception."""
    spec = load_scenario(SCENARIOS / "experiment1.toml")
    other = load_scenario(SCENARIOS / "experiment3.toml")
    source = runs_of(spec, other)
    runs = [run for run, _ in source.list_runs()]
    demons = [[d.name for d in spec.demons], [d.name for d in other.demons]]
    view = LiveView(source, port=free_port(), fps=200.0)
    view.start()
    errors: list[BaseException] = []
    stop = threading.Event()

    def choose(key: str) -> None:
        k = 0
        while not stop.is_set():
            try:
                view.show(key, runs[k % 2], demons[k % 2][::-1], large=k % 3 == 0)
            except BaseException as exc:
                errors.append(exc)
            k += 1

    try:
        clients = [RawClient(view, TAB), RawClient(view, "dashboard-tab-2")]
        choosers = [threading.Thread(target=choose, args=(key,), daemon=True) for key in (TAB, "dashboard-tab-2")]
        for thread in choosers:
            thread.start()
        for _ in range(6):  # clients arrive and leave while the choices keep coming
            late = RawClient(view, TAB)
            drawn = view.frames
            wait_until(lambda drawn=drawn: view.frames > drawn + 5, "the view thread to draw frames", 20.0)
            late.close()
        frames = view.frames
        stop.set()
        for thread in choosers:
            thread.join(timeout=10)
        assert errors == []
        wait_until(lambda: view.frames > frames + 5, "the view thread to go on drawing", 20.0)
        failures = [r for r in caplog.records if r.name.startswith("horde.view") and r.levelname == "ERROR"]
        assert failures == [], [r.getMessage() for r in failures]
        assert {c.viewer.panel.run_id for c in clients} <= set(runs)
    finally:
        stop.set()
        view.stop()
        source.manager.stop()
