"""examples/05 runs a Horde through the public API only and reaches the exact answers."""

from __future__ import annotations

import ast
import importlib.util
import math
import re
from pathlib import Path
from types import ModuleType

import pytest

import horde

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "05_horde_in_python.py"
ANY_WORLD = ROOT / "examples" / "08_any_world_in_python.py"


def load_example(path: Path = EXAMPLE) -> ModuleType:
    spec = importlib.util.spec_from_file_location(path.stem, path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_example_reaches_the_exact_answers(capsys: pytest.CaptureFixture[str]) -> None:
    assert load_example().main(["--steps", "20000"]) == 0
    out = capsys.readouterr().out
    worst = re.search(r"worst relative error over both demons and every cell: ([0-9.]+)%", out)
    assert worst is not None, out
    assert float(worst.group(1)) < 1.0, out
    assert out.count("%") == 2 * 14 + 1, "14 lattice points (16 cells minus the goal and the pit) per demon"


def test_a_short_run_is_visibly_not_there_yet(capsys: pytest.CaptureFixture[str]) -> None:
    """The comparison can fail: 200 steps leave the demons far from the truth, and the script says so."""
    load_example().main(["--steps", "200"])
    worst = re.search(r"every cell: ([0-9.]+)%", capsys.readouterr().out)
    assert worst is not None and float(worst.group(1)) > 10.0


@pytest.mark.parametrize("example", [EXAMPLE, ANY_WORLD], ids=lambda path: path.stem)
def test_the_examples_use_only_the_public_api(example: Path) -> None:
    tree = ast.parse(example.read_text())
    imported = [n for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) and (n.module or "").startswith("horde")]
    assert [n.module for n in imported] == ["horde"]
    assert all(alias.name in horde.__all__ for n in imported for alias in n.names)


@pytest.mark.timeout(120)
def test_simulation_runs_a_gymnasium_world_as_it_runs_the_grid() -> None:
    spec = horde.load_scenario(ROOT / "scenarios" / "mountaincar-nexting.toml")
    sim = horde.Simulation(spec)
    sim.run(1000)
    predictions = sim.predictions()
    assert sim.total_steps == 1000 and list(predictions) == [d.name for d in spec.demons]
    assert len(predictions) == 131 and all(math.isfinite(v) for v in predictions.values())
    assert len(set(predictions.values())) > 100  # learned: not one value (the zeros it started from) for all
    grid = horde.Simulation(horde.load_scenario(ROOT / "scenarios" / "experiment1.toml"))
    grid.run(1000)
    assert grid.total_steps == 1000 and set(grid.predictions()) == {"base", "steps_to_end"}


def test_a_stream_world_has_no_simulation_and_is_pointed_to_learn_log() -> None:
    spec = horde.load_scenario(ROOT / "scenarios" / "mountaincar-log.toml")
    with pytest.raises(ValueError, match=r"horde\.learn_log\(spec, path\)"):
        horde.Simulation(spec)
    result = horde.learn_log(spec, str(ROOT / "examples" / "data" / "mountaincar-pump.csv"))
    assert result.learned == result.records > 0 and not result.refused
    compared = [d for d in result.demons if d.mean_prediction is not None and d.mean_return is not None]
    assert compared and all(abs(d.mean_prediction - d.mean_return) < 0.1 * abs(d.mean_return) + 0.05 for d in compared)


@pytest.mark.timeout(120)
def test_run_protocol_runs_a_gymnasium_protocol() -> None:
    spec = horde.load_scenario(ROOT / "scenarios" / "mountaincar-nexting.toml")
    small = spec.model_copy(
        update={
            "demons": spec.demons[:2],
            "protocol": spec.protocol.model_copy(
                update={
                    "episodes": 1,
                    "evaluation": spec.protocol.evaluation.model_copy(update={"states": 2, "rollouts": 2}),
                }
            ),
        }
    )
    result = horde.run_protocol(small)
    assert isinstance(result, horde.GymProtocolResult)
    assert [d.name for d in result.demons] == [d.name for d in spec.demons[:2]]
    assert all(d.truth is not None and math.isfinite(d.truth) for d in result.demons)


def test_the_any_world_example_runs(capsys: pytest.CaptureFixture[str]) -> None:
    assert load_example(ANY_WORLD).main(["--steps", "200"]) == 0
    out = capsys.readouterr().out
    assert "mountaincar-nexting (gymnasium): 200 steps" in out and "131 predictions" in out
    assert "baird (gymnasium): 200 steps" in out
    learned = re.search(r"(\d+) of (\d+) records learned", out)
    assert learned is not None and learned.group(1) == learned.group(2) != "0", out


def test_the_public_api_resolves() -> None:
    assert all(getattr(horde, name, None) is not None for name in horde.__all__)
