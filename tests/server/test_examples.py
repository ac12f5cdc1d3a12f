"""The REST examples run (with small sizes) against the in-process server and succeed."""

from __future__ import annotations

import importlib.util
from pathlib import Path
from types import ModuleType

import pytest
from fastapi.testclient import TestClient

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
SMALL = {
    "01_first_run.py": ["--episodes", "20"],
    "02_world_and_demons.py": ["--seconds", "0.6", "--rollouts", "50"],
    "03_experiment1_truth.py": ["--episodes", "30", "--rollouts", "50"],
    "04_snapshot_resume.py": ["--steps", "500"],
}


def load(path: Path) -> ModuleType:
    spec = importlib.util.spec_from_file_location(f"example_{path.stem}", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_every_example_is_covered() -> None:
    # 05 runs a Horde without the server: tests/test_public_api.py runs it. 06 records a log and 07 replays one
    # over a real socket: tests/worlds/test_streams.py runs them.
    others = ["05_horde_in_python.py", "06_record_a_log.py", "07_stream_replay.py"]
    assert sorted(p.name for p in EXAMPLES.glob("[0-9]*.py")) == sorted([*SMALL, *others])


@pytest.mark.parametrize("name", sorted(SMALL))
def test_example_runs(name: str, client: TestClient, capsys: pytest.CaptureFixture[str]) -> None:
    module = load(EXAMPLES / name)
    assert module.__doc__ and name[:2] in module.__doc__
    assert module.main(SMALL[name], client=client) == 0
    assert capsys.readouterr().out
