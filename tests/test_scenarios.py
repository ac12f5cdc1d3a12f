"""Every scenario file validates, and its world keeps the environment contract (STYLE item 7)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from grids import lamp, lamp_terminal
from horde.core.check import WorldCheckError
from horde.core.simulation import Simulation
from horde.core.world import World
from horde.scenarios import ScenarioError, list_scenarios, load_scenario, parse_scenario, scenario_dir
from horde.spec import RunSpec
from horde.worlds.check import check_world

SCENARIOS = sorted(scenario_dir().glob("*.toml"))


def test_the_thesis_scenarios_are_all_there() -> None:
    names = {s.name for s in list_scenarios()}
    expected = {f"experiment2-{a}" for a in ("whole", "start", "none", "large", "small")}
    expected |= {"experiment1", "experiment3", "experiment3-base"}
    assert expected <= names
    assert any(name.startswith("classroom") for name in names)


@pytest.mark.parametrize("path", SCENARIOS, ids=[p.stem for p in SCENARIOS])
def test_every_scenario_keeps_the_world_contract_on_both_engines(path: Path) -> None:
    spec = load_scenario(path)
    assert spec.description, "every scenario explains itself in one line"
    check_world(spec)


# The world kinds the scenarios do not all cover: a start rectangle beside walls and terminals, colour-
# dependent terminal rewards, slip and noise together.
KINDS: dict[str, dict[str, Any]] = {
    "rect-start-walls-lamp": {
        "width": 400,
        "height": 300,
        "step": 50,
        "slip": 0.2,
        "noise": 7,
        "start": [0, 0, 250, 300],
        "max_steps": 60,
        "regions": [
            {"name": "wall", "kind": "obstacle", "rect": [100, 0, 150, 200]},
            {"name": "pit", "kind": "terminal", "rect": [0, 250, 100, 300], "reward": -1},
            lamp_terminal("door", [300, 100, 400, 200], on=2, off=-2),
            lamp([200, 0, 300, 100], on=(1, 0.3), off=(-1, 0.7)),
        ],
    },
    "open-field-no-terminal": {"width": 300, "height": 300, "step": 100, "start": [150, 150], "max_steps": 25},
}


@pytest.mark.parametrize("world", KINDS.values(), ids=KINDS.keys())
def test_every_world_kind_keeps_the_world_contract_on_both_engines(world: dict[str, Any]) -> None:
    spec = RunSpec.model_validate({"world": world, "demons": [{"name": "bumps", "cumulant": {"sensor": "bump"}}]})
    check_world(spec)


@pytest.mark.parametrize(
    ("breakage", "message"),
    [
        ("unseeded reset", "same seed, other run"),
        ("sensor out of range", "sensor 'x' read"),
        ("engines apart", "the engines disagree"),
    ],
)
def test_the_world_checker_catches_a_broken_world(breakage: str, message: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """Each rule of check_world can fail: break world.py one way and the checker must say so."""
    spec = load_scenario(scenario_dir() / "experiment1.toml")
    if breakage == "unseeded reset":
        reset = World.reset
        monkeypatch.setattr(World, "reset", lambda self, rng, batch=1: reset(self, np.random.default_rng(), batch))
        spec = spec.model_copy(update={"world": spec.world.model_copy(update={"start": [0.0, 0.0, 500.0, 100.0]})})
    elif breakage == "sensor out of range":
        sensors = World.sensors
        monkeypatch.setattr(World, "sensors", lambda self, state, tr: sensors(self, state, tr) + (np.arange(
            len(self.sensor_names)) == 0) * spec.world.width)  # fmt: skip
    else:
        move = World.move
        monkeypatch.setattr(World, "move", lambda self, x, y, a, o=None: move(self, x, y, (a + 1) % 4, o))
    with pytest.raises(WorldCheckError, match=message):
        check_world(spec)


@pytest.mark.parametrize("path", SCENARIOS, ids=[p.stem for p in SCENARIOS])
def test_same_seed_same_run(path: Path) -> None:
    spec = load_scenario(path)
    if spec.world.kind != "grid":  # check_world runs a Gymnasium world twice on one seed; a stream draws nothing
        pytest.skip(f"a {spec.world.kind} world: its same-seed check is check_world's")
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
