"""`horde serve` on a data directory it cannot write (issue 24, item 5) exits with one clear line, no traceback.

Root writes through permission bits, so for root the directory is made immutable (`chattr +i`) instead of
read-only; where neither can be done the read-only cases are skipped. A data path that is a file fails alike
for every user.
"""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

from horde.runs.store import Store
from serving import free_port


@contextmanager
def read_only(directory: Path) -> Iterator[None]:
    """`directory` unwritable for this process until the block ends."""
    if os.geteuid() != 0:
        directory.chmod(0o555)
        try:
            yield
        finally:
            directory.chmod(0o755)
        return
    if subprocess.run(["chattr", "+i", str(directory)], capture_output=True).returncode != 0:
        pytest.skip("root, and the directory cannot be made immutable (chattr +i) here")
    try:
        yield
    finally:
        subprocess.run(["chattr", "-i", str(directory)], check=True)


def serve(data: Path) -> subprocess.CompletedProcess[str]:
    env = {k: v for k, v in os.environ.items() if not k.startswith("HORDE_")}
    command = [sys.executable, "-m", "horde.cli", "serve", "--data", str(data), "--port", str(free_port()), "--no-view"]
    return subprocess.run(command, capture_output=True, text=True, env=env, timeout=90)


def assert_one_line_refusal(result: subprocess.CompletedProcess[str], data: Path) -> None:
    assert result.returncode == 2, (result.returncode, result.stdout, result.stderr)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in result.stderr, result.stderr
    assert lines[0].startswith("refusing to start: the data directory") and str(data) in lines[0], lines


@pytest.mark.parametrize("with_database", [False, True], ids=["empty", "with-database"])
def test_a_read_only_data_directory_is_refused_in_one_line(tmp_path: Path, with_database: bool) -> None:
    data = tmp_path / "data"
    data.mkdir()
    if with_database:
        Store(data).close()
    with read_only(data):
        assert_one_line_refusal(serve(data), data)


def test_a_data_path_that_is_a_file_is_refused_in_one_line(tmp_path: Path) -> None:
    data = tmp_path / "data"
    data.write_text("not a directory")
    assert_one_line_refusal(serve(data), data)
