"""SimulationSource: snapshots, value maps, commands and the history ring."""

from __future__ import annotations

import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from horde.core.simulation import Simulation
from horde.scenarios import load_scenario
from horde.view.history import Ring
from horde.view.sim_source import SimulationSource, cell_centres
from horde.view.source import ViewSource

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"


@pytest.fixture
def source() -> Iterator[SimulationSource]:
    source = SimulationSource(
        [load_scenario(SCENARIOS / "experiment1.toml"), load_scenario(SCENARIOS / "experiment3.toml")],
        hz=200.0,
    )
    yield source
    source.close()


def test_it_is_a_view_source(source: SimulationSource) -> None:
    assert isinstance(source, ViewSource)
    assert source.list_runs() == [("experiment1-1", "experiment1"), ("experiment3-2", "experiment3")]


def test_step_matches_a_simulation_with_the_same_seed(source: SimulationSource) -> None:
    spec = load_scenario(SCENARIOS / "experiment1.toml")
    twin = Simulation(spec)
    positions = [twin.position]
    for _ in range(7):
        episode = twin.episode
        twin.step()
        positions = [twin.position] if twin.episode != episode else [*positions, twin.position]
    source.step("experiment1-1", 7)
    snap = source.snapshot("experiment1-1")
    assert (snap.x, snap.y) == twin.position
    assert snap.trail == tuple(positions)
    assert snap.total_steps == 7 and snap.episode == twin.episode
    assert snap.status == "paused"
    assert snap.predictions == pytest.approx(twin.predictions())
    assert list(snap.history.steps) == list(range(1, 8))
    assert snap.history.predictions["steps_to_end"][-1] == pytest.approx(twin.predictions()["steps_to_end"])


def test_snapshot_restricted_to_some_demons(source: SimulationSource) -> None:
    source.step("experiment3-2", 3)
    snap = source.snapshot("experiment3-2", ["colour"])
    assert set(snap.predictions) == set(snap.rupee) == set(snap.history.predictions) == {"colour"}
    assert snap.indicator_colors["lamp"] in ("yellow", "purple")
    assert source.snapshot("experiment3-2", ["nobody", "base"]).predictions.keys() == {"base"}
    with pytest.raises(KeyError):
        source.snapshot("no-such-run")


def test_value_map_and_greedy_actions_follow_the_grid_convention(source: SimulationSource) -> None:
    source.step("experiment1-1", 200)
    values = source.value_map("experiment1-1", "base", 5)
    greedy = source.greedy_actions("experiment1-1", "base", 5)
    assert values.shape == (5, 5) and greedy is not None and greedy.shape == (5, 5)
    assert greedy.dtype.kind == "i" and set(np.unique(greedy)) <= {0, 1, 2, 3}
    assert source.greedy_actions("experiment1-1", "steps_to_end", 5) is None
    xs, ys = cell_centres(500.0, 500.0, 5)
    assert (xs[1], ys[1]) == (150.0, 50.0) and (xs[5], ys[5]) == (50.0, 150.0)  # row j holds y_j
    snap = source.snapshot("experiment1-1")
    i, j = int(snap.x // 100), int(snap.y // 100)
    assert values[j, i] == pytest.approx(snap.predictions["base"])  # same features in the agent's cell


def test_play_pause_speed_and_reset(source: SimulationSource) -> None:
    run = "experiment1-1"
    source.set_hz(run, None)
    source.play(run)
    deadline = time.monotonic() + 10.0
    while source.snapshot(run).total_steps < 100 and time.monotonic() < deadline:
        time.sleep(0.02)
    assert source.snapshot(run).status == "running"
    source.pause(run)
    time.sleep(0.1)
    paused_at = source.snapshot(run).total_steps
    assert paused_at >= 100
    time.sleep(0.1)
    assert source.snapshot(run).total_steps == paused_at
    assert source.snapshot(run).hz is None
    source.set_hz(run, 50.0)
    assert source.snapshot(run).hz == 50.0
    source.reset(run)
    snap = source.snapshot(run)
    assert snap.total_steps == 0 and snap.status == "created" and len(snap.history.steps) == 0


def test_the_ring_keeps_the_last_samples_oldest_first() -> None:
    ring = Ring(3, 2)
    for step in range(1, 6):
        ring.append(step, np.array([step, -step]), np.array([0.1 * step, 0.0]))
    steps, predictions, rupee = ring.columns([1])
    assert list(steps) == [3, 4, 5]
    assert predictions[:, 0].tolist() == [-3, -4, -5]
    assert rupee.shape == (3, 1)
    assert Ring(4, 1).columns([0])[0].size == 0
