"""Baird's star in the live view: seven states coloured by a demon's values, the agent on its state."""

from __future__ import annotations

import numpy as np
import pytest

from horde.runs.manager import RunManager
from horde.scenarios import load_scenario, scenario_dir
from horde.view.manager_source import ManagerSource
from horde.view.star import star_nodes, star_positions

from .viewers import RawClient, started_by_hand


def test_the_star_draws_seven_states_their_values_and_the_agent() -> None:
    values = np.array([3.0, 3, 3, 3, 3, 3, 12])  # Baird's initial weights: 2 + 1 above, 10 + 2 below
    nodes = {node.name: node for node in star_nodes("td", values, state=6)}
    where = star_positions()
    assert where.shape == (7, 2) and (where[:6, 1] > where[6, 1]).all()  # the six upper states above the lower
    assert [nodes[f"/star/value{s}"].text for s in (0, 6)] == ["s1: 3", "s7: 12"]
    assert nodes["/star/agent"].position[:2] == pytest.approx(tuple(where[6]))
    assert sum(nodes["/star/state6"].color) > sum(nodes["/star/state0"].color)  # brighter is higher (viridis)
    assert nodes["/star/solid"].points is not None and nodes["/star/solid"].points.shape == (6, 2, 3)
    assert nodes["/star/title"].text.startswith("td: the value of each state, 3 to 12")
    frozen = {node.name: node for node in star_nodes("td", np.zeros(7), state=2, diverged=True)}
    assert "diverged" in frozen["/star/title"].text
    assert frozen["/star/agent"].position[:2] == pytest.approx(tuple(where[2]))


def test_a_baird_run_is_drawn_as_the_star_in_the_live_view() -> None:
    manager = RunManager()
    run = manager.create(load_scenario(scenario_dir() / "baird.toml"), hz=50.0).id
    source = ManagerSource(manager)
    view = started_by_hand(source)
    try:
        client = RawClient(view, "dashboard-tab-1")
        view.show("dashboard-tab-1", run)
        view.refresh()
        client.viewer.panel.value_demon = "gtd"
        view.refresh()
        drawn = client.viewer.applier.drawn
        assert {f"/star/state{s}" for s in range(7)} <= set(drawn) and "/phase/map" not in drawn
        assert client.viewer.panel.phase_x is None, "no phase-plane axes to choose for the star"
        assert drawn["/star/title"][0].text.startswith("gtd: the value of each state, 3 to 12")
        demon, values, state, diverged = source.star(run, "gtd")  # type: ignore[misc]
        assert demon == "gtd" and not diverged
        np.testing.assert_allclose(values, [3, 3, 3, 3, 3, 3, 12])
        assert drawn["/star/agent"][0].position[:2] == pytest.approx(tuple(star_positions()[state]))
        with pytest.raises(KeyError):
            source.star(run, "nobody")
    finally:
        view.stop()
        manager.stop()
