"""The REST examples run (with small sizes) against the in-process server and succeed."""

from __future__ import annotations

import importlib.util
from pathlib import Path
from types import ModuleType
from typing import Any

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
    # 05 and 08 run a Horde without the server: tests/test_public_api.py runs them. 06 records a log and 07
    # replays one over a real socket: tests/worlds/test_streams.py runs them.
    others = ["05_horde_in_python.py", "06_record_a_log.py", "07_stream_replay.py", "08_any_world_in_python.py"]
    assert sorted(p.name for p in EXAMPLES.glob("[0-9]*.py")) == sorted([*SMALL, *others])


@pytest.mark.parametrize("name", sorted(SMALL))
def test_example_runs(name: str, client: TestClient, capsys: pytest.CaptureFixture[str]) -> None:
    module = load(EXAMPLES / name)
    assert module.__doc__ and name[:2] in module.__doc__
    assert module.main(SMALL[name], client=client) == 0
    assert capsys.readouterr().out
    assert client.get("/api/runs").json() == []  # it deleted the runs it made


def test_an_example_asked_to_keep_its_runs_leaves_them(client: TestClient) -> None:
    assert (
        load(EXAMPLES / "04_snapshot_resume.py").main([*SMALL["04_snapshot_resume.py"], "--keep"], client=client) == 0
    )
    assert len(client.get("/api/runs").json()) == 2  # the original and its imported copy


def test_an_example_that_fails_midway_still_deletes_its_runs(client: TestClient) -> None:
    """The deletion sits in a `finally`: a request that fails after the run was made (here an evaluation
    with a bad demon: its 422 raises) does not leave the run behind."""
    module = load(EXAMPLES / "03_experiment1_truth.py")
    original_post = client.post

    def failing_post(url: str, **kwargs: Any) -> Any:
        if url.endswith("/evaluate"):
            raise RuntimeError("the network went away")
        return original_post(url, **kwargs)

    client.post = failing_post  # type: ignore[method-assign]
    try:
        with pytest.raises(RuntimeError, match="network went away"):
            module.main(SMALL["03_experiment1_truth.py"], client=client)
    finally:
        client.post = original_post  # type: ignore[method-assign]
    assert client.get("/api/runs").json() == []
