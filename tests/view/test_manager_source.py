"""The server's runs behind the live view's ViewSource protocol (ManagerSource), and the GUI's commands."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field

import numpy as np
import pytest

from horde.runs.manager import RunManager
from horde.runs.run_setup import Limits
from horde.scenarios import load_scenario, scenario_dir
from horde.view.manager_source import ManagerSource
from horde.view.source import CommandRefusedError, ViewSource

from .viewers import RawClient, started_by_hand


@pytest.fixture
def source() -> Iterator[ManagerSource]:
    manager = RunManager(None, Limits())
    yield ManagerSource(manager)
    manager.stop()


def test_it_is_a_view_source(source: ManagerSource) -> None:
    assert isinstance(source, ViewSource)
    assert source.list_runs() == []
    with pytest.raises(KeyError):
        source.snapshot("nope")


def test_snapshot_follows_the_run(source: ManagerSource) -> None:
    spec = load_scenario(scenario_dir() / "experiment3.toml")
    run_id = source.manager.create(spec).id
    assert source.list_runs() == [(run_id, "experiment3")]
    first = source.snapshot(run_id)
    assert (first.x, first.y) == (200.0, 200.0)
    assert first.trail == ((200.0, 200.0),)
    assert first.indicator_colors["lamp"] in {"yellow", "purple"}
    source.step(run_id, 3)
    after = source.snapshot(run_id, ["base"])
    assert after.total_steps == 3
    assert set(after.predictions) == set(after.rupee) == {"base"}
    assert after.trail[-1] == (after.x, after.y)
    assert len(after.history.steps) == len(after.history.predictions["base"]) > 0


def test_value_map_and_greedy_actions(source: ManagerSource) -> None:
    spec = load_scenario(scenario_dir() / "experiment1.toml")
    run_id = source.manager.create(spec).id
    source.step(run_id, 500)
    values = source.value_map(run_id, "steps_to_end", 10)
    assert values.shape == (10, 10) and np.isfinite(values).all()
    actions = source.greedy_actions(run_id, "base", 10)
    assert actions is not None and actions.shape == (10, 10)
    assert set(np.unique(actions)) <= {0, 1, 2, 3}
    assert source.greedy_actions(run_id, "steps_to_end", 10) is None, "prediction demons have no greedy action"
    with pytest.raises(KeyError):
        source.value_map(run_id, "nobody", 10)


def test_commands_reach_the_run(source: ManagerSource) -> None:
    spec = load_scenario(scenario_dir() / "experiment1.toml")
    run_id = source.manager.create(spec).id
    source.set_hz(run_id, 200.0)
    source.play(run_id)
    assert source.snapshot(run_id).status == "running"
    source.pause(run_id)
    assert source.snapshot(run_id).status == "paused"
    assert source.snapshot(run_id).hz == 200.0
    source.reset(run_id)
    assert source.snapshot(run_id).total_steps == 0
    with pytest.raises(CommandRefusedError, match="cannot pause a created run"):
        source.pause(run_id)
    with pytest.raises(CommandRefusedError, match=r"hz must lie in \[") as refused:
        source.set_hz(run_id, -1.0)
    assert "hz" in str(refused.value)
    source.manager.delete(run_id)
    with pytest.raises(KeyError):
        source.play(run_id)


@dataclass
class Client:
    """A viser client as a GUI event carries it: the notifications it was sent."""

    client_id: int = 7
    notes: list[tuple[str, str, str]] = field(default_factory=list)

    def add_notification(self, title: str, body: str, color: str = "") -> None:
        self.notes.append((title, body, color))


@dataclass
class Click:
    client: Client
    client_id: int = 7


def test_a_refused_gui_command_is_told_to_the_client_who_clicked(source: ManagerSource) -> None:
    spec = load_scenario(scenario_dir() / "experiment1.toml")
    run_id = source.manager.create(
        spec.model_copy(update={"protocol": spec.protocol.model_copy(update={"episodes": 1})})
    ).id
    source.step(run_id, 5000)
    assert source.snapshot(run_id).status == "finished"
    view = started_by_hand(source)
    try:
        panel = RawClient(view, "dashboard-tab-1").viewer.panel
        view.show("dashboard-tab-1", run_id)
        view.refresh()
        assert panel.run_id == run_id
        clicker, other = Click(Client(7)), Client(8)
        panel.commands.command(clicker, source.play)
        assert clicker.client.notes == [("Not done", "cannot start a finished run: reset it to run again", "red")]
        assert other.notes == [], "the others are not told"
        panel.commands.command(clicker, source.reset)  # accepted: nothing to tell
        assert len(clicker.client.notes) == 1 and source.snapshot(run_id).status == "created"
        source.manager.delete(run_id)
        panel.commands.command(clicker, source.play)
        assert clicker.client.notes[-1][0] == "Run gone"
    finally:
        view.stop()
