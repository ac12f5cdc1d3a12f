"""A TOML file nested too deep for the (recursive) parser is a one-line error naming the file and line
(issue 24, item 8): `horde run` on a 5,000-deep array printed a RecursionError traceback."""

from __future__ import annotations

from pathlib import Path

import pytest

from horde.cli import main
from horde.scenarios import ScenarioError
from horde.studies.files import parse_study

DEPTH = 5000


def deep_toml() -> str:
    return f'name = "deep"\n\nx = {"[" * DEPTH}{"]" * DEPTH}\n'


def test_horde_run_on_a_5000_deep_array_is_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "deep.toml"
    path.write_text(deep_toml())
    assert main(["run", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.strip().splitlines() == [f"error: {path}:3: invalid TOML: arrays or tables nested too deep to read"]


def test_a_deep_study_file_is_refused_alike() -> None:
    with pytest.raises(ScenarioError, match=r"^deep.toml:3: invalid TOML: .*nested too deep"):
        parse_study(deep_toml(), "deep.toml")
