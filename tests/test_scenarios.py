"""Every scenario file validates, and its world keeps the environment contract (STYLE item 7)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from horde.core.simulation import Simulation
from horde.core.world import World
from horde.scenarios import ScenarioError, list_scenarios, load_scenario, parse_scenario, scenario_dir

SCENARIOS = sorted(scenario_dir().glob("*.toml"))


def test_the_thesis_scenarios_are_all_there() -> None:
    names = {s.name for s in list_scenarios()}
    expected = {f"experiment2-{a}" for a in ("whole", "start", "none", "large", "small")}
    expected |= {"experiment1", "experiment3", "experiment3-base"}
    assert expected <= names
    assert any(name.startswith("classroom") for name in names)


@pytest.mark.parametrize("path", SCENARIOS, ids=[p.stem for p in SCENARIOS])
def test_world_contract(path: Path) -> None:
    spec = load_scenario(path)
    assert spec.description, "every scenario explains itself in one line"
    world = World(spec.world)
    rng = np.random.default_rng(0)
    state = world.reset(rng, batch=8)
    assert state.x.shape == state.y.shape == state.steps.shape == (8,)
    assert (state.steps == 0).all()
    ended = np.zeros(8, dtype=bool)
    for _ in range(spec.world.max_steps):
        actions = rng.integers(0, 4, size=8)
        state, transition = world.step(state, actions, rng)
        sensors = world.sensors(state, transition)
        assert sensors.shape == (8, len(spec.world.sensor_names()))
        assert np.isfinite(sensors).all()
        assert not (transition.terminated & transition.truncated).any(), "terminated and truncated are apart"
        assert ((state.x >= 0) & (state.x < spec.world.width) & (state.y >= 0) & (state.y < spec.world.height)).all()
        assert not (world.inside(state.x, state.y) & world.is_obstacle).any(), "never inside an obstacle"
        ended |= transition.terminated | transition.truncated
        if ended.all():
            break
    assert ended.all(), "every episode ends by termination or by truncation at max_steps"


@pytest.mark.parametrize("path", SCENARIOS, ids=[p.stem for p in SCENARIOS])
def test_same_seed_same_run(path: Path) -> None:
    spec = load_scenario(path)
    runs = []
    for _ in range(2):
        sim = Simulation(spec, np.random.default_rng(42))
        trace = [(sim.step().action, *sim.position) for _ in range(150)]
        runs.append((trace, sim.horde_state.prediction.copy()))
    assert runs[0][0] == runs[1][0]
    np.testing.assert_array_equal(runs[0][1], runs[1][1])


def test_errors_name_the_file_line_and_field(tmp_path: Path) -> None:
    bad = tmp_path / "bad.toml"
    bad.write_text('name = "bad"\n\n[world]\nwidth = 500\nstep = -3\n')
    with pytest.raises(ScenarioError) as info:
        load_scenario(bad)
    message = str(info.value)
    assert f"{bad}:5: world.step:" in message
    assert "greater than 0" in message


def test_syntax_errors_name_the_line() -> None:
    with pytest.raises(ScenarioError, match=r"x.toml:2: invalid TOML"):
        parse_scenario('name = "x"\nworld = [\n', "x.toml")


def test_unknown_keys_are_rejected() -> None:
    with pytest.raises(ScenarioError, match=r"demons\.0\.cumulent"):
        parse_scenario('[[demons]]\nname = "a"\ncumulent = 1\n', "typo.toml")


def test_an_impossible_start_names_the_file_line_and_field() -> None:
    text = (
        'name = "walled"\n\n[world]\nstart = [100, 200, 200, 300]\n\n'
        '[[world.regions]]\nname = "wall"\nkind = "obstacle"\nrect = [100, 200, 200, 300]\n'
    )
    with pytest.raises(ScenarioError, match=r"walled.toml:4: world.start: the start rectangle has no cell"):
        parse_scenario(text, "walled.toml")
