"""The server's runs behind the live view's ViewSource protocol (ManagerSource)."""

from __future__ import annotations

import numpy as np
import pytest

from horde.runs.manager import RunManager
from horde.runs.run_setup import Limits
from horde.scenarios import load_scenario, scenario_dir
from horde.view.manager_source import ManagerSource
from horde.view.source import ViewSource


@pytest.fixture
def source() -> ManagerSource:
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
    source.pause(run_id)  # refused by the run's state (not running): ignored, like the GUI's buttons
