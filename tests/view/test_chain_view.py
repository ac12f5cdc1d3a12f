"""A chain world in the live view: every state's value as a line beside the truth, the agent on its state (the
book's figure 9.1 drawn as the run learns)."""

from __future__ import annotations

import numpy as np
import pytest

from horde.runs.manager import RunManager
from horde.scenarios import load_scenario, scenario_dir
from horde.view.chain import HEIGHT, chain_nodes
from horde.view.manager_source import ManagerSource

from .viewers import RawClient, started_by_hand


def test_the_chain_draws_the_values_the_truth_and_the_agent() -> None:
    states = np.arange(1, 6)
    exact = states / 6.0
    nodes = {n.name: n for n in chain_nodes("td", states, np.zeros(5), exact, exact, agent=3)}
    values, truth = nodes["/chain/values"].points, nodes["/chain/truth"].points
    assert values is not None and truth is not None and values.shape == truth.shape == (4, 2, 3)
    assert (np.diff(truth[:, 0, 1]) > 0).all() and np.ptp(values[:, :, 1]) == 0  # the truth climbs; 0 is flat
    assert truth[-1, 1, 1] == pytest.approx(HEIGHT / 2)  # the highest value at the top
    assert "/chain/fixed" not in nodes  # the fixed point is the truth: not drawn twice
    assert nodes["/chain/agent"].position[0] == pytest.approx(nodes["/chain/state2"].position[0])
    assert "diverged" in chain_nodes("td", states, np.zeros(5), exact, exact, 3, diverged=True)[1].text


def test_a_chain_run_is_drawn_state_by_state_in_the_live_view() -> None:
    manager = RunManager()
    run = manager.create(load_scenario(scenario_dir() / "boyan-chain.toml"), hz=50.0).id
    source = ManagerSource(manager)
    view = started_by_hand(source)
    try:
        manager.get(run).step(300)
        client = RawClient(view, "dashboard-tab-1")
        view.show("dashboard-tab-1", run)
        view.refresh()
        client.viewer.panel.value_demon = "tdrc"
        view.refresh()
        drawn = client.viewer.applier.drawn
        assert {"/chain/values", "/chain/truth", "/chain/agent"} <= set(drawn) and "/phase/map" not in drawn
        assert client.viewer.panel.phase_x is None, "no phase-plane axes to choose for a chain"
        title = drawn["/chain/title"][0].text
        assert title.startswith("tdrc: the value of each state") and "RMSVE" in title
        picture = source.chain(run, "tdrc")
        assert picture is not None and list(picture.states) == list(range(12, 0, -1))
        assert picture.exact is not None and picture.exact == pytest.approx(-2.0 * picture.states)
        assert picture.values[0] < -5  # 300 steps of learning: state 12 on its way to -24
        with pytest.raises(KeyError):
            source.chain(run, "nobody")
    finally:
        view.stop()
        manager.stop()
